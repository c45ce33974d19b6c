"""Influence functions chosen per part (``parts[k].influence``).

Expectations are closed forms computed here, not earlier output of the code:

* the bulk shape tensor is the lattice sum K = sum_k omega(|k| dx) (k dx)(k dx)^T dx^3
  with the function written out below, and gamma = sum_k omega dx^3;
* patch test: u = H X gives F = I + H wherever the family is complete and, under
  a uniform stress, no force two horizons from the surface — for any omega;
* parts with different functions: sum_i f_i V_i = 0 (Newton's third law holds
  only if omega_i uses i's function and omega_j j's on both sides of every bond),
  and f is the gradient of sum_i V_i P_i : F_i + E_hg with P held fixed;
* a change of function alone is a change of resolution: the interface
  correction removes its ghost force.
"""
import numpy as np
import pytest
from conftest import granite, make_scene, scene_dict

from mpipd.input import scene as sc
from mpipd.input.geometry import LayerTable, balls_inside
from mpipd.input.schema import SceneError
from mpipd.parallel.decomp import decompose, halo_width, local_points
from mpipd.solver import Simulation

OMEGA = {
    "quadratic": lambda d, r: (d - r) ** 2,
    "constant": lambda d, r: np.ones_like(r),
    "inverse": lambda d, r: d / r,
}
NAMES = list(OMEGA)
H = np.array([[1e-3, 2e-4, -3e-4], [5e-4, -2e-3, 1e-4], [-1e-4, 3e-4, 1.5e-3]])
SIGMA = np.array([3e6, -1e6, 2e6, 5e5, -7e5, 4e5])


def box(lo, hi):
    return {"kind": "box", "lo": lo, "hi": hi}


def one_part(name, lo, hi, dx=1e-3):
    d = scene_dict(box(lo, hi), dx=dx)
    d["parts"][0]["influence"] = name
    return make_scene(d)


def interior(x, lo, hi, margin):
    return np.all((x > np.asarray(lo) + margin) & (x < np.asarray(hi) - margin), axis=1)


@pytest.mark.parametrize("name", NAMES)
def test_bulk_shape_tensor_is_the_lattice_sum(team, name):
    lo, hi, dx = [0, 0, 0], [0.009, 0.009, 0.009], 1e-3
    sim = Simulation(one_part(name, lo, hi, dx), team)
    p, c = sim.points, sim.corr
    i = int(np.argmin(np.linalg.norm(p.x[:p.n_owned] - 0.0045, axis=1)))   # the centre
    delta = p.horizon[i]
    k = np.arange(-3, 4)
    xi = dx * np.stack(np.meshgrid(k, k, k, indexing="ij"), -1).reshape(-1, 3)
    r = np.linalg.norm(xi, axis=1)
    xi, r = xi[(r > 0) & (r < delta)], r[(r > 0) & (r < delta)]
    assert len(r) == 122
    w = OMEGA[name](delta, r) * dx ** 3
    K = np.einsum("n,ni,nj->ij", w, xi, xi)
    np.testing.assert_allclose(np.linalg.inv(c.Kinv[i]), K, rtol=1e-12, atol=1e-12 * K.max())
    assert c.trK[i] == pytest.approx(np.trace(K), rel=1e-13)
    assert c.gamma[i] == pytest.approx(w.sum(), rel=1e-13)


@pytest.mark.parametrize("name", NAMES)
def test_patch_test(team, name):
    lo, hi, dx = [0, 0, 0], [0.016, 0.016, 0.016], 1e-3
    sim = Simulation(one_part(name, lo, hi, dx), team)
    p = sim.points
    n = p.n_owned
    sim.u[:] = p.x @ H.T
    sim.v[:] = 0.0
    sim.corr.deform(sim.u, sim.v)
    delta = p.horizon[0]
    inside = interior(p.x[:n], lo, hi, delta)
    assert inside.sum() > 50
    F = sim.corr.F[inside]
    np.testing.assert_allclose(F, np.broadcast_to(np.eye(3) + H, F.shape), rtol=0, atol=1e-13)
    sim.corr.R[:] = np.eye(3)
    sim.corr.sigma[:] = SIGMA
    sim.compute_forces()
    deep = interior(p.x[:n], lo, hi, 2 * delta)
    assert deep.sum() > 5
    scale = np.abs(SIGMA).max() / dx
    assert np.abs(sim.f[deep]).max() < 1e-10 * scale
    assert np.abs(sim.f[~inside]).max() > 1e-3 * scale        # the surface carries traction


def mixed_parts(correction=False, dx_fine=0.5e-3):
    """Three boxes along x: constant (1 mm), inverse (dx_fine, 2.5 dx), quadratic (1 mm)."""
    parts = [{"name": "a", "material": "a", "dx": 1e-3, "influence": "constant",
              "shape": box([0, 0, 0], [0.006, 0.006, 0.006])},
             {"name": "b", "material": "b", "dx": dx_fine, "horizon_factor": 2.5,
              "influence": "inverse", "shape": box([0.006, 0, 0], [0.009, 0.006, 0.006])},
             {"name": "c", "material": "a", "dx": 1e-3,
              "shape": box([0.009, 0, 0], [0.015, 0.006, 0.006])}]
    d = scene_dict(None, parts=parts, hourglass=0.05)
    d["materials"] = {"a": granite(), "b": granite(shear_modulus=40e9, density=8000.0)}
    d["solver"]["interface_correction"] = correction
    return make_scene(d)


def random_state(sim, seed):
    rng = np.random.default_rng(seed)
    n = sim.points.n_owned
    sim.u[:] = rng.normal(size=sim.u.shape) * 1e-6
    sim.corr.sigma[:] = rng.normal(size=(n, 6)) * 1e7
    sim.corr.R[:] = np.eye(3)
    sim.corr.deform(sim.u, sim.v)
    sim.compute_forces()
    return rng


def test_parts_with_different_functions_conserve_momentum(team):
    sim = Simulation(mixed_parts(), team)
    assert sorted(set(sim.points.influence)) == [0, 1, 2]
    random_state(sim, 5)
    V = sim.points.volume[:sim.points.n_owned]
    net = (sim.f * V[:, None]).sum(axis=0)
    scale = (np.abs(sim.f) * V[:, None]).sum()
    assert np.abs(net).max() < 1e-12 * scale


def test_force_is_gradient_of_energy_across_functions(team):
    sim = Simulation(mixed_parts(), team)
    rng = random_state(sim, 6)
    p, c = sim.points, sim.corr
    n = p.n_owned
    S = np.zeros((n, 3, 3))
    s = c.sigma
    S[:, 0, 0], S[:, 1, 1], S[:, 2, 2] = s[:, 0], s[:, 1], s[:, 2]
    S[:, 1, 2] = S[:, 2, 1] = s[:, 3]
    S[:, 0, 2] = S[:, 2, 0] = s[:, 4]
    S[:, 0, 1] = S[:, 1, 0] = s[:, 5]
    F0 = c.F.copy()
    P = np.linalg.det(F0)[:, None, None] * S @ np.linalg.inv(F0).transpose(0, 2, 1)
    V = p.volume[:n]

    def phi(u):                      # F - F0: only the family of the moved point counts
        c.deform(u, sim.v)
        return float(np.sum(V * np.einsum("nij,nij->n", P, c.F - F0))) + c.hourglass_energy(u)

    # points of each part, near the part boundaries (x = 6 and 9 mm) where families mix
    x = p.x[:n, 0]
    near = ((x > 0.004) & (x < 0.006), (x > 0.006) & (x < 0.0075), (x > 0.009) & (x < 0.011))
    picks = [rng.choice(np.flatnonzero(m)) for m in near]
    h = 1e-8                         # phi is quadratic in u: central differences are exact
    for k in picks:
        for a in range(3):
            up, um = sim.u.copy(), sim.u.copy()
            up[k, a] += h
            um[k, a] -= h
            grad = (phi(up) - phi(um)) / (2 * h)
            assert abs(sim.f[k, a] * V[k] + grad) <= 1e-6 * abs(grad), (k, a)


def same_lattice_two_functions(correction):
    """Quadratic beside constant, one lattice and horizon: only omega changes at x = 14 mm."""
    W = 0.018
    parts = [{"name": "q", "material": "granite", "dx": 1e-3, "shape": box([0, 0, 0],
                                                                          [0.014, W, W])},
             {"name": "k", "material": "granite", "dx": 1e-3, "influence": "constant",
              "shape": box([0.014, 0, 0], [0.028, W, W])}]
    d = scene_dict(None, parts=parts)
    d["solver"]["interface_correction"] = correction
    return make_scene(d)


@pytest.mark.parametrize("correction", [True, False])
def test_change_of_function_is_an_interface(team, correction):
    sim = Simulation(same_lattice_two_functions(correction), team)
    p = sim.points
    n = p.n_owned
    sim.u[:] = p.x @ H.T
    sim.corr.deform(sim.u, sim.v)
    assert np.abs(sim.corr.F - (np.eye(3) + H)).max() < 1e-13      # exact everywhere
    sim.corr.R[:] = np.eye(3)
    sim.corr.sigma[:] = SIGMA
    sim.compute_forces()
    f = np.abs(sim.f).max(axis=1) / (np.abs(SIGMA).max() / p.dx[:n])
    deep = balls_inside(sim.scene.parts, p.x[:n], np.full(n, 2 * p.horizon.max()))
    assert deep.sum() >= 20
    if correction:
        assert sim.interface is not None and sim.interface.n_active >= deep.sum()
        assert f[deep].max() < 1e-10                 # measured 2.6e-14
    else:
        assert sim.interface is None
        assert f[deep].max() > 1e-2        # the change of omega's ghost force (measured 0.097)


def test_ghosts_carry_their_parts_function():
    scene = mixed_parts()
    table = LayerTable.from_parts(scene.parts, scene.material_ids)
    slabs = decompose(table, 3, halo_width(scene))
    codes = {"quadratic": 0, "constant": 1, "inverse": 2}
    want = np.array([codes[q.influence] for q in scene.parts])
    for r in range(3):
        p = local_points(scene, slabs, r)
        assert p.influence.dtype == np.uint8 and p.n_local > p.n_owned
        np.testing.assert_array_equal(p.influence, want[p.part])


def test_zones_inherit_the_function():
    shape = {"kind": "annulus", "center": [0.0, 0.0], "inner_radius": 0.003, "radius": 0.02,
             "z": [0.0, 0.004]}
    parts = [{"name": "r", "material": "granite", "dx": 1e-3, "shape": shape,
              "influence": "inverse", "grade": {"dx_outer": 2e-3, "zones": 3},
              "band": {"dx": 3e-4, "width": 2e-3}}]
    scene = make_scene(scene_dict(None, parts=parts))
    assert len(scene.parts) == 4
    assert all(q.influence == "inverse" for q in scene.parts)


def test_unknown_function_is_a_one_line_error():
    d = scene_dict(box([0, 0, 0], [0.006, 0.006, 0.006]))
    d["parts"][0]["influence"] = "cubic"
    with pytest.raises(SceneError) as e:
        make_scene(d)
    msg = str(e.value)
    assert msg.startswith("parts.0.influence: unknown influence function 'cubic'")
    assert "quadratic" in msg and "constant" in msg and "inverse" in msg
    assert "\n" not in msg


def test_gas_parts_keep_the_quadratic_function():
    with pytest.raises(SceneError, match=r"^parts\.0\.influence: the explosive gas"):
        sc.load("blast_demo", ['parts.0.influence="constant"'])
    assert sc.load("blast_demo", ['parts.1.influence="constant"'])[0].parts[1].influence \
        == "constant"
