"""The correspondence gather kernels (mpipd.kernels.nosb) on hand-built lattices.

* gather_forces at every level against Eq. 1 written out bond by bond in numpy
  (the multi-rate weights of kernels.classes, no springs, contact or viscosity);
* gather_reweight, the one-pass change of the forces when step classes change,
  against the difference of two full gathers, with springs, contact and viscosity
  on, and against momentum conservation (equal and opposite bond impulses).
"""
import numpy as np
import pytest
from scipy.spatial import cKDTree

from mpipd.kernels import nosb
from mpipd.kernels.layout import FD_H, FD_SPRING, FD_VISC_L, FD_VISC_Q, FD_WIDTH_VISCOUS


def lattice(seed, n=5, dx=1.0e-3, m=3.0):
    """A jittered n^3 lattice with CSR families within m dx, sorted by index."""
    rng = np.random.default_rng(seed)
    g = np.arange(n) * dx
    x = np.stack(np.meshgrid(g, g, g, indexing="ij"), -1).reshape(-1, 3)
    x = x + rng.uniform(-0.1, 0.1, x.shape) * dx
    delta = m * dx
    tree = cKDTree(x)
    rows = [sorted(j for j in tree.query_ball_point(p, delta) if j != i) for i, p in enumerate(x)]
    offsets = np.zeros(len(x) + 1, np.int64)
    offsets[1:] = np.cumsum([len(r) for r in rows])
    nbr = np.concatenate(rows).astype(np.int64)
    N = len(x)
    vol = rng.uniform(0.8, 1.2, N) * dx ** 3
    horizon = np.full(N, delta)
    infl = np.zeros(N, np.int64)            # the quadratic influence function
    wi = np.empty(len(nbr))
    wj = np.empty(len(nbr))
    rinv = np.empty(len(nbr))
    nosb.bond_influence(x, horizon, infl, offsets, nbr, wi, wj, rinv)
    u = rng.normal(0.0, 0.02 * dx, x.shape)
    v = rng.normal(0.0, 1.0, x.shape)
    fd = np.zeros((N, FD_WIDTH_VISCOUS))
    fd[:, :9] = rng.normal(0.0, 1.0e9, (N, 9)) / delta ** 5
    fd[:, FD_H] = rng.uniform(0.5, 1.5, N) * 1.0e9 / delta ** 5
    cbb = np.full(N, 18 * 50e9 / (np.pi * delta ** 4))
    # spring reference maps (rest length |G xi|; read only where an end is on the springs)
    G = np.eye(3) + rng.normal(0.0, 0.1, (N, 3, 3))
    return dict(x=x, u=u, v=v, vol=vol, horizon=horizon, wi=wi, wj=wj, rinv=rinv, offsets=offsets,
                nbr=nbr, fd=fd, G=G, cbb=cbb, rng=rng)


def bonds(L):
    """Every bond (i, j) of the lattice with its xi and Y, for Eq. 1 written out in numpy."""
    N = len(L["x"])
    i = np.repeat(np.arange(N), np.diff(L["offsets"]))
    j = L["nbr"]
    xi = L["x"][j] - L["x"][i]
    return i, j, xi, xi + L["u"][j] - L["u"][i]


def gather(L, klass, level, broken=None, contact=False, fd=None):
    N = len(L["x"])
    fd = L["fd"] if fd is None else fd
    broken = np.zeros(len(L["nbr"]), np.uint8) if broken is None else broken
    kmin = np.zeros(N, np.uint8)
    f = np.empty((N, 3))
    fv = np.empty((N, 3) if fd.shape[1] > 11 else (0, 3))
    nosb.gather_forces(L["x"], L["u"], L["v"], L["vol"], L["horizon"], L["wi"], L["wj"], L["rinv"],
                       L["offsets"], L["nbr"], broken, fd, L["G"], L["cbb"], contact, f, fv,
                       klass, kmin, level)
    return f, fv


@pytest.mark.parametrize("level", [0, 1, 2])
def test_gather_is_eq1_with_the_multirate_weights(level):
    L = lattice(1)
    fd = L["fd"][:, :11].copy()                  # no viscosity
    N = len(L["x"])
    klass = L["rng"].integers(0, 3, N).astype(np.uint8)
    f, _ = gather(L, klass, level, fd=fd)
    # Eq. 1 bond by bond: V_j [r_i omega_i (B_i xi + h_i Y) + r_j omega_j (B_j xi + h_j Y)]
    i, j, xi, Y = bonds(L)
    r = np.where(klass <= level, 2.0 ** klass, 0.0)
    B = fd[:, :9].reshape(N, 3, 3)
    h = fd[:, FD_H]

    def side(p, w):
        return (r[p] * w)[:, None] * (np.einsum("bij,bj->bi", B[p], xi) + h[p][:, None] * Y)

    fb = L["vol"][j][:, None] * (side(i, L["wi"]) + side(j, L["wj"]))
    want = np.zeros((N, 3))
    np.add.at(want, i, fb)
    scale = np.abs(want).max()
    assert scale > 0.0
    assert np.abs(f - want).max() <= 1e-12 * scale


def test_springs_stretch_from_their_reference_maps():
    """Every point on the bond springs (B = h = 0): Eq. 1 is the sum of the two
    half-springs, (c_p / 2) s_p Y/|Y| with s_p = (|Y| - |G_p xi|) / |xi| for each end p
    whose horizon holds the bond, written out here in numpy; and a point whose G is
    its affine F feels no spring force in that affine field."""
    L = lattice(5)
    N = len(L["x"])
    fd = np.zeros((N, 11))
    fd[:, FD_SPRING] = 1.0
    level = 2
    klass = L["rng"].integers(0, 3, N).astype(np.uint8)
    f, _ = gather(L, klass, level, fd=fd)
    i, j, xi, Y = bonds(L)
    r, ly = np.linalg.norm(xi, axis=1), np.linalg.norm(Y, axis=1)
    wt = 2.0 ** klass.astype(float)

    def half(p, w):
        s = (ly - np.linalg.norm(np.einsum("bij,bj->bi", L["G"][p], xi), axis=1)) / r
        return np.where(w > 0, 0.5 * L["cbb"][p] * s * wt[p], 0.0)

    fb = (L["vol"][j] * (half(i, L["wi"]) + half(j, L["wj"])) / ly)[:, None] * Y
    want = np.zeros((N, 3))
    np.add.at(want, i, fb)
    assert np.abs(f - want).max() <= 1e-12 * np.abs(want).max()
    # an affine field Y = A xi with every G = A: the springs are at rest
    A = np.array([[2.3, 0.1, 0.0], [-0.2, 1.9, 0.05], [0.0, 0.1, 0.6]])
    L["u"] = L["x"] @ (A - np.eye(3)).T
    L["G"] = np.broadcast_to(A, (N, 3, 3)).copy()
    f, _ = gather(L, klass, level, fd=fd)
    assert np.abs(f).max() <= 1e-9 * np.abs(want).max()


def full_setup(seed):
    L = lattice(seed)
    N = len(L["x"])
    rng = L["rng"]
    fd = L["fd"]
    # some on the bond springs: B, h and the viscosity 0 there (force_data, viscosity_data)
    spring = rng.random(N) < 0.15
    fd[spring, :FD_SPRING] = 0.0
    fd[spring, FD_SPRING] = 1.0
    on = (rng.random(N) < 0.5) & ~spring                          # viscosity where compressed
    fd[on, FD_VISC_L] = rng.uniform(0.5, 1.5, on.sum()) * 1e3
    fd[on, FD_VISC_Q] = rng.uniform(0.5, 1.5, on.sum()) * 1e3
    # a bond breaks for both its ends: by the pair (i < j), the same draw from each side
    i = np.repeat(np.arange(N), np.diff(L["offsets"]))
    j = L["nbr"]
    draw = rng.random((N, N))
    broken = (draw[np.minimum(i, j), np.maximum(i, j)] < 0.3).astype(np.uint8)
    L["u"] *= 0.0
    L["u"] += rng.normal(0.0, 0.15e-3, L["u"].shape)              # pairs close enough to touch
    return L, broken


@pytest.mark.parametrize("seed", [2, 3])
def test_reweight_is_the_difference_of_two_gathers(seed):
    L, broken = full_setup(seed)
    N = len(L["x"])
    rng = L["rng"]
    old = rng.integers(0, 3, N).astype(np.uint8)
    new = old.copy()
    moved = rng.random(N) < 0.1
    new[moved] = rng.integers(0, 3, moved.sum())
    assert (new != old).any()
    top = 2
    f_old, fv_old = gather(L, old, top, broken, contact=True)
    f_new, fv_new = gather(L, new, top, broken, contact=True)
    for rows in (np.arange(N), np.sort(rng.choice(N, N // 3, replace=False))):
        g = np.empty((len(rows), 3))
        gv = np.empty((len(rows), 3))
        nosb.gather_reweight(L["x"], L["u"], L["v"], L["vol"], L["horizon"], L["wi"], L["wj"], L["rinv"],
                             L["offsets"], L["nbr"], broken, L["fd"], L["G"], L["cbb"], True, rows,
                             old, new, top, g, gv)
        want = (f_new - f_old)[rows]
        scale = np.abs(f_new).max()
        assert np.abs(want).max() > 1e-6 * scale                 # the classes did change forces
        assert np.abs(g - want).max() <= 1e-12 * scale
        assert np.abs(gv - (fv_new - fv_old)[rows]).max() <= 1e-12 * np.abs(fv_new).max()
    # every bond's change of impulse is equal and opposite: sum_i V_i g_i = 0
    g = np.empty((N, 3))
    gv = np.empty((N, 3))
    nosb.gather_reweight(L["x"], L["u"], L["v"], L["vol"], L["horizon"], L["wi"], L["wj"], L["rinv"],
                         L["offsets"], L["nbr"], broken, L["fd"], L["G"], L["cbb"], True, np.arange(N),
                         old, new, top, g, gv)
    net = (L["vol"][:, None] * g).sum(axis=0)
    assert np.abs(net).max() <= 1e-12 * (L["vol"][:, None] * np.abs(g)).sum()


def test_unchanged_classes_change_nothing():
    L, broken = full_setup(4)
    N = len(L["x"])
    k = L["rng"].integers(0, 3, N).astype(np.uint8)
    g = np.full((N, 3), np.nan)
    gv = np.full((N, 3), np.nan)
    nosb.gather_reweight(L["x"], L["u"], L["v"], L["vol"], L["horizon"], L["wi"], L["wj"], L["rinv"],
                         L["offsets"], L["nbr"], broken, L["fd"], L["G"], L["cbb"], True, np.arange(N),
                         k, k.copy(), 2, g, gv)
    assert (g == 0.0).all() and (gv == 0.0).all()
