"""Bond-spring fallback: two points cannot form an invertible shape tensor, so
both act as bond-based springs, f = c s Y/|Y| V_j with c = 18 K / (pi delta^4)."""
import math

import numpy as np
import pytest
from conftest import make_scene, scene_dict

from mpipd.solver import Simulation


def test_two_points_act_as_a_spring(team):
    dx = 1e-3
    sim = Simulation(make_scene(scene_dict({"kind": "box", "lo": [0, 0, 0],
                                            "hi": [dx, dx, 2 * dx]}, dx=dx)), team)
    assert sim.points.n_owned == 2 and sim.corr.n_spring == 2
    stretch = 1e-3
    sim.u[1, 2] = stretch * dx                     # gid 1 is the upper point
    sim.initialize()
    delta = sim.points.horizon[0]
    c = 18.0 * 21.9e9 / (math.pi * delta ** 4)
    expected = c * stretch * dx ** 3               # force density on the lower point, +z
    np.testing.assert_allclose(sim.f[0], [0, 0, expected], rtol=1e-12)
    np.testing.assert_allclose(sim.f[1], [0, 0, -expected], rtol=1e-12)


# -------------------------------------------------- the stable-step test of the fallback
def _reduced_family(dt_fraction):
    """An 9^3 granite block whose centre point keeps only its bonds in the plane z = 0
    and the one to (0, 0, +dx): K stays invertible (det K passes the RCOND test) but its
    z eigenvalue has lost most of its reference value.  ``dt_fraction``: dt over the
    critical step the fallback rule compares with (mpipd.model.stability.part_critical_dt)."""
    from mpipd.model.stability import part_critical_dt
    dx = 1e-3
    d = scene_dict({"kind": "box", "lo": [0, 0, 0], "hi": [9 * dx] * 3}, dx=dx)
    dtc = part_critical_dt(make_scene(d))[0]
    d["time"]["dt"] = dt_fraction * dtc
    return d, dx


def _centre_and_keep(sim, dx):
    """The centre point, and the intact-bond mask of its family under the reduction."""
    x = sim.points.x
    c = np.argmin(np.linalg.norm(x[:sim.points.n_owned] - 4.5 * dx, axis=1))
    fam = sim.families
    b0, b1 = fam.offsets[c], fam.offsets[c + 1]
    xi = x[fam.nbr[b0:b1]] - x[c]
    keep = (np.abs(xi[:, 2]) < 1e-9) | (np.linalg.norm(xi - [0, 0, dx], axis=1) < 1e-9)
    return c, b0, b1, xi, keep


def _lambda_min(xi, delta, V):
    """lambda_min of K = sum_j omega xi (x) xi V_j, omega = (delta - |xi|)^2 (Eq. 4 with
    the quadratic influence), computed here with numpy's eigvalsh."""
    r = np.linalg.norm(xi, axis=1)
    w = np.where(r < delta, (delta - r) ** 2, 0.0) * V
    return np.linalg.eigvalsh(np.einsum("b,bi,bj->ij", w, xi, xi))[0]


def test_a_point_whose_shape_tensor_is_too_soft_for_the_step_takes_the_springs(team):
    """floor = (dt / dt_c)^2 lambda_min(K^0) (model.correspondence.stable_floor): the
    reduced family's lambda_min(K) / lambda_min(K^0) = q, computed here; with
    (dt / dt_c)^2 at 0.9 q the point keeps its correspondence force, at 1.1 q it takes
    the bond springs — at an invertible K the RCOND test alone would pass (checked)."""
    from mpipd.kernels.layout import CORRESPONDENCE, SPRING_K
    from mpipd.model.correspondence import RCOND
    d, dx = _reduced_family(0.5)
    sim = Simulation(make_scene(d), team)
    c, b0, b1, xi, keep = _centre_and_keep(sim, dx)
    delta, V = sim.points.horizon[c], dx ** 3
    q = _lambda_min(xi[keep], delta, V) / _lambda_min(xi, delta, V)
    assert 1e-3 < q < 0.1                                   # a soft, invertible K
    r = np.linalg.norm(xi[keep], axis=1)
    w = (delta - r) ** 2 * V
    K = np.einsum("b,bi,bj->ij", w, xi[keep], xi[keep])
    assert np.linalg.det(K) > RCOND * (np.trace(K) / 3) ** 3
    for frac, code in ((0.9, CORRESPONDENCE), (1.1, SPRING_K)):
        d, _ = _reduced_family(np.sqrt(frac * q))
        sim = Simulation(make_scene(d), team)
        assert sim.corr.n_spring == 0                        # at rest: nobody on springs
        sim.families.broken[b0:b1] = ~keep
        sim.corr.rebuild_shape(np.array([c]))
        assert sim.corr.spring[c] == code, frac
        assert sim.corr.n_spring == (code == SPRING_K)


def test_stable_floor_never_exceeds_the_reference_eigenvalue(team):
    """At dt above the critical step (``--force``) the floor is lambda_min(K^0) itself
    (min(1, dt / dt_c)): a point at rest stays on its correspondence force."""
    d, dx = _reduced_family(1.7)
    sim = Simulation(make_scene(d), team)
    c, *_, xi, _ = _centre_and_keep(sim, dx)
    lam0 = _lambda_min(xi, sim.points.horizon[c], dx ** 3)
    assert sim.corr.floor[c] == pytest.approx(lam0, rel=1e-10)
    assert sim.corr.n_spring == 0


def _jointed_block(frac):
    """A 10^3 granite block (dx 1 mm, never failing) cut by two joints, x = 4.3 mm and
    y = 4.3 mm, into four columns; dt = ``frac`` of the critical step."""
    from mpipd.model.stability import part_critical_dt
    d = scene_dict({"kind": "box", "lo": [0, 0, 0], "hi": [10e-3] * 3}, dx=1e-3)
    d["materials"]["granite"]["tension"] = {"sigma_st": -1e15}
    d["joints"] = [{"point": [4.3e-3, 0, 0], "normal": [1.0, 0, 0]},
                   {"point": [0, 4.3e-3, 0], "normal": [0, 1.0, 0]}]
    d["solver"]["contact"] = True
    d["time"]["dt"] = frac * part_critical_dt(make_scene(d))[0]
    return make_scene(d)


def test_a_face_cut_by_a_joint_starts_on_its_correspondence_force(team):
    """The floor's reference is the family at the start (model.correspondence.
    stable_floor): at dt = 0.95 dt_c no point of the jointed block starts on the
    springs, although the points along the joints, measured against their whole family
    (the rule before), lie below (0.95)^2 of it; lambda_min of both families computed
    here with numpy."""
    from mpipd.model.stability import part_critical_dt
    frac = 0.95
    sim = Simulation(_jointed_block(frac), team)
    p, fam = sim.points, sim.families
    n = p.n_owned
    assert fam.broken.any()
    lam_start, lam_whole = np.empty(n), np.empty(n)
    for i in range(n):
        b0, b1 = fam.offsets[i], fam.offsets[i + 1]
        xi = p.x[fam.nbr[b0:b1]] - p.x[i]
        lam_whole[i] = _lambda_min(xi, p.horizon[i], p.volume[i])
        lam_start[i] = _lambda_min(xi[fam.broken[b0:b1] == 0], p.horizon[i], p.volume[i])
    assert (lam_start / lam_whole < frac ** 2).sum() > 0    # the whole-family rule sprang these
    ratio = sim.scene.time.dt / part_critical_dt(sim.scene)[0]      # frac, to rounding
    # (the kernel's closed-form eigenvalue agrees with eigvalsh to 1e-8 at corners)
    np.testing.assert_allclose(sim.corr.floor, ratio ** 2 * lam_start, rtol=1e-6)
    assert sim.corr.n_spring == 0 and sim.corr.count_floor() == 0


def test_a_face_cut_by_a_joint_is_stable_beyond_the_critical_step(team):
    """The ground for the start's reference: on the correspondence force, the jointed
    block's faces are stepped stably at 1.5 dt_c (random velocities, 400 steps: the
    energy stays within 1 % of its start; measured once, studies/validation/notes.md §31,
    the jointed block first blows up between 1.65 and 1.7 dt_c, the uncut one between
    1.7 and 1.8), where the whole-family rule gave its joint points a stable step of
    sqrt(lambda_min(K) / lambda_min(K^0)) dt_c < dt_c."""
    sim = Simulation(_jointed_block(1.5), team)
    n = sim.points.n_owned
    assert sim.corr.n_spring == 0
    sim.v[:n] = np.random.default_rng(5).uniform(-1.0, 1.0, (n, 3))
    sim.initialize()
    e0 = sim.energies().total
    worst = 0.0
    for _ in range(400):
        sim.step()
        worst = max(worst, abs(sim.energies().total / e0 - 1.0))
    assert worst < 0.01, worst
    assert sim.corr.n_spring == 0


# -------------------------------------------------- the springs' reference map
def _stretched_block(team):
    """A 7^3 granite block (dx 1 mm) in the affine field u = (A - I) x of a large,
    mostly plastic-sized deformation A (the copper tube of studies/validation/notes.md §40
    is blown out to 2.3-2.5 times its radius), F computed (initialize); its centre."""
    dx = 1e-3
    sim = Simulation(make_scene(scene_dict({"kind": "box", "lo": [0, 0, 0],
                                            "hi": [7 * dx] * 3}, dx=dx)), team)
    A = np.array([[2.3, 0.2, 0.0], [-0.1, 2.4, 0.1], [0.0, 0.05, 0.45]])
    sim.u[:] = sim.points.x @ (A - np.eye(3)).T
    sim.initialize()
    n = sim.points.n_owned
    c = int(np.argmin(np.linalg.norm(sim.points.x[:n] - 3.5 * dx, axis=1)))
    np.testing.assert_allclose(sim.corr.F[c], A, rtol=0, atol=1e-12)
    return sim, A, c


def _reference_spring_energy(sim, c, A, keep=None):
    """Point c's spring energy if its springs measured stretch from the reference
    (s = |A xi|/|xi| - 1, the paper's G = I): V_c sum_j (c_bb / 4) s^2 |xi| V_j."""
    p, fam = sim.points, sim.families
    b0, b1 = fam.offsets[c], fam.offsets[c + 1]
    xi = p.x[fam.nbr[b0:b1]] - p.x[c]
    r = np.linalg.norm(xi, axis=1)
    ok = (r < p.horizon[c]) & (np.ones(len(r), bool) if keep is None else keep)
    s = np.linalg.norm(xi @ A.T, axis=1) / r - 1.0
    return p.volume[c] * np.sum((sim.corr.cbb[c] / 4) * s[ok] ** 2 * r[ok]
                                * p.volume[fam.nbr[b0:b1]][ok])


def test_a_point_whose_shape_tensor_goes_singular_keeps_its_configuration_unloaded(team):
    """Bonds break until K is singular (two opposite bonds left): the point takes the
    springs with its F of before as reference map G, so in its affine field they hold
    nothing; measured from the reference they would hold E0 (computed here)."""
    from mpipd.kernels.layout import SPRING_K
    sim, A, c = _stretched_block(team)
    fam, x = sim.families, sim.points.x
    b0, b1 = fam.offsets[c], fam.offsets[c + 1]
    xi = x[fam.nbr[b0:b1]] - x[c]
    keep = (np.abs(np.abs(xi[:, 0]) - 1e-3) < 1e-9) & (np.abs(xi[:, 1:]).sum(axis=1) < 1e-9)
    assert keep.sum() == 2
    fam.broken[b0:b1] = ~keep
    sim.corr.rebuild_shape(np.array([c]), sim.u)
    assert sim.corr.spring[c] == SPRING_K
    np.testing.assert_allclose(sim.corr.G[c], A, rtol=0, atol=1e-12)
    E0 = _reference_spring_energy(sim, c, A, keep)
    E = sim.corr.potentials(np.array([c]), sim.u)[0, 1]
    assert E0 > 1.0e-3 and abs(E) <= 1e-12 * E0


def test_a_point_whose_F_turns_singular_takes_its_last_F_as_spring_reference(team):
    """F of the centre point turned singular (det F < 0) while F_old is the affine A:
    force_data switches it to the springs (SPRING_F) with G = A, their energy in the
    affine field is 0, and the ledger books the jump as energy removed (the hourglass
    energy of the singular F), not created; from the reference the springs would
    have held E0 > 10 times that hourglass energy."""
    from mpipd.kernels.layout import SPRING_F
    sim, A, c = _stretched_block(team)
    np.testing.assert_allclose(sim.corr.F_old[c], A, rtol=0, atol=1e-12)
    sim.corr.F[c] = np.diag([-1.0, 1.0, 1.0]) @ A
    hg = sim.corr.potentials(np.array([c]), sim.u)[0, 0]
    j0 = sim.ledger.jumps
    sim.corr.force_data(sim.u, sim.ledger)
    assert sim.corr.spring[c] == SPRING_F
    np.testing.assert_allclose(sim.corr.G[c], A, rtol=0, atol=1e-12)
    E0 = _reference_spring_energy(sim, c, A)
    assert E0 > 10 * hg > 0
    assert abs(sim.corr.potentials(np.array([c]), sim.u)[0, 1]) <= 1e-12 * E0
    assert sim.ledger.jumps - j0 == pytest.approx(hg, rel=1e-9)


# -------------------------------------------------- a point switched to the springs keeps its state
def _loaded_point_on_springs(team):
    """A 7^3 block of Table 1's JH2 granite with the tension model (dx 1 mm, at rest),
    its centre point given by hand a uniaxial-strain state — axial deviator
    -2/3 s, lateral +1/3 s with s = 230 MPa, pressure 35 MPa (what the rock near the
    borehole wall carries) — and then cut down to two opposite bonds, so that its
    shape tensor is singular and it takes the bond springs (SPRING_K)."""
    from mpipd.kernels.layout import SPRING_K
    dx = 1e-3
    d = scene_dict({"kind": "box", "lo": [0, 0, 0], "hi": [7 * dx] * 3}, dx=dx, dt=2e-8)
    d["materials"] = {"granite": {"model": "jh2", "tension": {"sigma_st": -6.9e6, "c1": 0.33,
                                                               "rate0": 0.4}}}
    sim = Simulation(make_scene(d), team)
    sim.initialize()
    n = sim.points.n_owned
    c = int(np.argmin(np.linalg.norm(sim.points.x[:n] - 3.5 * dx, axis=1)))
    s_eq, p = 230e6, 35e6
    a = s_eq / 1.5                      # von Mises of diag(-a, a/2, a/2) is 1.5 a
    sim.corr.sigma[c] = [-a - p, 0.5 * a - p, 0.5 * a - p, 0.0, 0.0, 0.0]
    g = sim.corr.groups[0]
    pos = int(np.flatnonzero(g.idx == c)[0])
    g.state["pressure"][pos] = p
    fam, x = sim.families, sim.points.x
    b0, b1 = fam.offsets[c], fam.offsets[c + 1]
    xi = x[fam.nbr[b0:b1]] - x[c]
    keep = (np.abs(np.abs(xi[:, 0]) - dx) < 1e-9) & (np.abs(xi[:, 1:]).sum(axis=1) < 1e-9)
    fam.broken[b0:b1] = ~keep
    sim.corr.rebuild_shape(np.array([c]), sim.u)
    assert sim.corr.spring[c] == SPRING_K
    return sim, c, pos, s_eq, p


def test_a_point_switched_to_the_springs_keeps_its_material_state(team):
    """The springs replace the point's force, not its material (paper §2.1): over
    steps on the springs its stress, damage and failure mode stay as they were.
    Computed here: with the placeholder kinematics (J = 1, d = 0) put through JH2,
    p would fall to 0 and the strength to sigma_HEL A (T/p_HEL)^N = 166 MPa < s,
    and the yield step's plastic strain (s - sigma_y) / 3G = 8.3e-4 exceeds
    eps_f = D1 (T/p_HEL)^D2 = 2.6e-4: D = 1 in the first step (the old code's
    failure of every switched point)."""
    sim, c, pos, s_eq, p = _loaded_point_on_springs(team)
    mat = sim.corr.groups[0].material
    ts = mat.T / mat.p_HEL
    sy0 = mat.sigma_hel * mat.A * ts ** mat.N
    assert sy0 < s_eq and (s_eq - sy0) / (3 * mat.shear_modulus) > mat.D1 * ts ** mat.D2
    before = sim.corr.sigma[c].copy()
    for _ in range(3):
        sim.step()
    g = sim.corr.groups[0]
    assert sim.mode[c] == 0
    assert g.state["D"][pos] == 0.0
    assert g.state["pressure"][pos] == p
    np.testing.assert_array_equal(sim.corr.sigma[c], before)
    assert not (sim.mode == 255).any()                      # MODE_HELD never left behind
