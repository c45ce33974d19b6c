"""Crossing-bond rule (paper §2.4, Fig. 3) on hand-built geometry, and PD damage."""
import numpy as np
import pytest

from mpipd.kernels.breakage import break_bonds, pd_damage

DX = 1e-3


def run(points, bonds, failed, dx=DX, material=None):
    """points: (n, 3) in units of DX; bonds: list of (i, j) for owned i (all points owned);
    dx: one spacing or one per point; material: one id per point (default all 0).
    Returns the set of broken (i, j)."""
    x = np.asarray(points, float) * DX
    n = len(x)
    gid = np.arange(n, dtype=np.int64)
    bonds = sorted(bonds)
    offsets = np.zeros(n + 1, np.int64)
    for i, _ in bonds:
        offsets[i + 1] += 1
    offsets = np.cumsum(offsets)
    nbr = np.array([j for _, j in bonds], np.int32)
    broken = np.zeros(len(nbr), np.uint8)
    touched = np.zeros(n, np.uint8)
    pk = np.array([k for k in failed for i in range(n)], np.int64)
    pi = np.array([i for k in failed for i in range(n)], np.int64)
    mat = np.zeros(n, np.int32) if material is None else np.asarray(material, np.int32)
    dxs = np.broadcast_to(np.asarray(dx, float), (n,)).copy()
    break_bonds(pk, pi, x, gid, dxs, mat, offsets, nbr, broken, touched)
    return {b for b, flag in zip(bonds, broken) if flag}, touched


# A at 0, B at 2 dx on the x axis; candidate failed points around the bond's middle
A, B = (0, 0, 0), (2, 0, 0)


@pytest.mark.parametrize("k,breaks", [
    ((1, 0, 0), True),          # on the segment
    ((1, 0.49, 0), True),       # just inside dx/2
    ((1, 0.51, 0), False),      # just outside
    ((1, 0.3, 0.39), True),     # |(0.3, 0.39)| = 0.492
    ((1, 0.3, 0.41), False),    # |(0.3, 0.41)| = 0.508
    ((2.45, 0, 0), True),       # beyond B's end, 0.45 dx from B
    ((2.55, 0, 0), False),      # beyond B's end, 0.55 dx from B
    ((-0.49, 0, 0), True),      # beyond A's end
])
def test_segment_rule(k, breaks):
    pts = [A, B, k]
    broken, _ = run(pts, [(0, 1), (1, 0)], failed=[2])
    assert broken == ({(0, 1), (1, 0)} if breaks else set())


def test_bonds_touching_failed_point_break_and_others_survive():
    # a line of 5 points; bonds between all pairs within 2 dx
    pts = [(i, 0, 0) for i in range(5)] + [(0, 3, 0)]
    bonds = [(i, j) for i in range(5) for j in range(5) if i != j and abs(i - j) <= 2]
    broken, touched = run(pts, bonds, failed=[2])
    # rule (a): all bonds of 2; rule (b): 1-3 passes through 2; 0-1, 3-4 survive
    want = {(i, j) for (i, j) in bonds if 2 in (i, j)} | {(1, 3), (3, 1)}
    assert broken == want
    assert list(touched[:5]) == [1, 1, 1, 1, 1]
    # a point far away breaks nothing
    broken, _ = run(pts, bonds, failed=[5])
    assert broken == set()


def test_both_directions_decided_alike_with_gid_order():
    # same geometry, the two directions listed with endpoints in either order:
    # the decision uses gid order, so it is the same bit for bit
    rng = np.random.default_rng(0)
    for _ in range(200):
        a, b = rng.uniform(-3, 3, 3), rng.uniform(-3, 3, 3)
        k = 0.5 * (a + b) + rng.normal(size=3) * 0.3
        broken, _ = run([a, b, k], [(0, 1), (1, 0)], failed=[2])
        assert broken in (set(), {(0, 1), (1, 0)})


def test_pd_damage_eq39():
    offsets = np.array([0, 4], np.int64)
    nbr = np.array([1, 2, 3, 4], np.int32)
    vol = np.array([1.0, 1.0, 2.0, 3.0, 4.0])
    broken = np.array([1, 0, 1, 0], np.uint8)
    phi = np.zeros(1)
    pd_damage(np.array([0], np.int64), offsets, nbr, broken, vol, phi)
    assert phi[0] == pytest.approx(1 - (2.0 + 4.0) / (1 + 2 + 3 + 4))


def test_a_coarse_failed_point_breaks_no_bond_of_another_material():
    """The paper's tube wall in miniature: a coarse rock point k (dx_k = 4 fine
    spacings, so its dx_k / 2 ball reaches 2 spacings) fails next to a line of fine
    copper points.  The copper-copper bonds passing within dx_k / 2 of x_k lie in
    the copper and stay intact; the copper-rock bonds crossing the ball (rule b)
    and k's own bonds (rule a) break, as does a rock-rock bond through the ball."""
    cu = [(i, 0, 0) for i in range(5)]                 # copper, material 1, dx 1
    k = (2, 1.5, 0)                                    # failed rock point, 1.5 from the line
    rock = [(2, 5.5, 0), (-2, 1.5, 0), (6, 1.5, 0)]    # rock, material 2, dx 4
    pts = cu + [k] + rock
    mat = [1] * 5 + [2] * 4
    dx = np.array([1.0] * 5 + [4.0] * 4) * DX
    K, R0, R1, R2 = 5, 6, 7, 8
    cc = [(i, j) for i in range(5) for j in range(5) if i != j]
    crk = [(i, R0) for i in range(5)] + [(R0, i) for i in range(5)]   # copper-rock, far side
    kb = [(K, i) for i in range(5)] + [(i, K) for i in range(5)]      # k's own bonds
    rr = [(R1, R2), (R2, R1)]                                          # rock-rock through k
    broken, _ = run(pts, cc + crk + kb + rr, failed=[K], dx=dx, material=mat)
    assert not (broken & set(cc)), "copper's own bonds must survive a rock failure"
    assert set(kb) <= broken and set(rr) <= broken
    # copper i -> rock R0 at (2, 5.5): the segment from (i, 0) passes within 2 of k
    # only for i = 1, 2, 3 (distance from (2, 1.5) to the segment, computed here)
    def dist(a, b, q):
        a, b, q = map(np.asarray, (a, b, q))
        t = np.clip(np.dot(q - a, b - a) / np.dot(b - a, b - a), 0, 1)
        return np.linalg.norm(a + t * (b - a) - q)
    want = {(i, R0) for i in range(5) if dist(cu[i], rock[0], k) <= 2.0}
    want |= {(R0, i) for (i, _) in want}
    assert want and broken & set(crk) == want
    # without the material condition (all one material) the copper bonds near k break
    broken1, _ = run(pts, cc, failed=[K], dx=dx)
    assert broken1 & set(cc)
