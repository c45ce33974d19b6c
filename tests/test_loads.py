"""Initial and boundary conditions, and the scene commands."""
import numpy as np
import pytest
from conftest import make_scene, run_cli, scene_dict

from mpipd.input import scene as sc
from mpipd.input.schema import SceneError
from mpipd.solver import Simulation


def test_fixed_end_holds_while_the_rest_moves(team):
    L = 0.02
    d = scene_dict({"kind": "box", "lo": [0, 0, 0], "hi": [L, 0.006, 0.006]}, dt=5e-8,
                   initial=[{"kind": "uniform_velocity",
                             "region": {"lo": [0.01, -1, -1], "hi": [1, 1, 1]},
                             "velocity": [2.0, 0.0, 0.0]}],
                   boundaries=[{"kind": "fixed", "region": {"lo": [-1, -1, -1],
                                                            "hi": [0.002, 1, 1]}}])
    sim = Simulation(make_scene(d), team)
    n = sim.points.n_owned
    x = sim.points.x[:n]
    fixed = x[:, 0] <= 0.002
    moving = x[:, 0] >= 0.01
    np.testing.assert_array_equal(sim.v[:n][moving], np.tile([2.0, 0, 0], (moving.sum(), 1)))
    assert np.all(sim.v[:n][~moving] == 0.0)
    for _ in range(100):
        sim.step()
    assert np.all(sim.u[:n][fixed] == 0.0) and np.all(sim.v[:n][fixed] == 0.0)
    assert sim.u[:n][moving, 0].mean() > 0.2 * 2.0 * 100 * 5e-8    # drifted forward (braked by the stretch wave)
    assert np.abs(sim.v[:n][~fixed & ~moving]).max() > 0.0           # the stretch propagated


def test_velocity_pulse_shape():
    scene, _ = sc.load("elastic_wave", ["parts.0.dx=0.002"])
    ic = scene.initial[0]
    x = np.array([[0.0, 0, 0], [0.01, 0, 0], [0.02, 0, 0], [0.03, 0, 0]])
    v = np.zeros_like(x)
    ic.apply(x, v)
    np.testing.assert_allclose(v[:, 0], [1.0, np.cos(np.pi / 4) ** 2, 0.0, 0.0], atol=1e-15)


def test_builtin_scenes_listed_valid_and_checkable():
    names = sc.builtin_scenes()
    assert "elastic_wave" in names
    res = run_cli(["scenes"])
    assert res.returncode == 0 and "elastic_wave" in res.stdout and "invalid" not in res.stdout
    res = run_cli(["check", "elastic_wave", "--ranks", "2"])
    assert res.returncode == 0, res.stderr
    for needle in ("49152 points", "Silling-Askari", "rank 1:", "MiB", "OK"):
        assert needle in res.stdout
    res = run_cli(["check", "elastic_wave", "--set", "time.dt=1e-6"])
    assert "TOO LARGE" in res.stdout


def test_override_parsing():
    scene, _ = sc.load("elastic_wave", ["initial.0.velocity=[2, 0, 0]", "scene.name=renamed",
                                        "parts.0.shape.hi=[0.1, 0.01, 0.01]"])
    assert scene.initial[0].velocity == (2.0, 0.0, 0.0)
    assert scene.name == "renamed"
    assert scene.parts[0].shape.hi == (0.1, 0.01, 0.01)


def test_check_reports_negative_tangent_eos():
    res = run_cli(["check", "granite_ring"])
    assert res.returncode == 0, res.stderr
    line = [ln for ln in res.stdout.splitlines() if "tangent" in ln]
    assert line and "0.00418..0.00582" in line[0]
    res = run_cli(["check", "granite_ring", "--set", "materials.granite.K2=0.0"])
    assert "tangent" not in res.stdout


def gaussian_scene(sigma=3e-3, v0=(0.6, -0.3, 0.2)):
    """A 37 mm cube (edge 12 sigma) at dx = 1 mm (sigma = 3 dx), the Gaussian centred on
    a lattice point.  The smallest horizon keeps the families (unused here) cheap."""
    h = 0.0185
    d = scene_dict({"kind": "box", "lo": [-h, -h, -h], "hi": [h, h, h]},
                   initial=[{"kind": "gaussian_velocity", "center": [0.0, 0.0, 0.0],
                             "sigma": sigma, "velocity": list(v0)}])
    d["parts"][0]["horizon_factor"] = 1.0
    return d


def test_gaussian_velocity_kinetic_energy(team):
    """KE = (1/2) rho |v0|^2 integral exp(-|x|^2 / sigma^2) d^3x = (1/2) rho |v0|^2 pi^1.5 sigma^3.

    The lattice sum differs from that integral by the aliasing terms of Poisson
    summation, 2 exp(-pi^2 sigma^2 / dx^2) = 1e-38 per axis at sigma = 3 dx, and by
    the faces, 3 erfc(18.5 mm / sigma) = 1e-17; what is left is the round-off of
    a 50653-term sum, ~sqrt(N) eps = 3e-14.  Measured: -3.5e-14, so the bound is
    2e-13 — tight enough to see the faces of a 31 mm cube (-5.3e-13, measured)."""
    sigma, v0 = 3e-3, np.array([0.6, -0.3, 0.2])
    sim = Simulation(make_scene(gaussian_scene(sigma, v0)), team)
    n = sim.points.n_owned
    ke = sim.energies().kinetic
    exact = 0.5 * 2660.0 * (v0 @ v0) * np.pi ** 1.5 * sigma ** 3
    assert abs(ke / exact - 1) < 2e-13, ke / exact - 1
    k = int(np.argmin(np.linalg.norm(sim.points.x[:n], axis=1)))
    assert np.linalg.norm(sim.points.x[k]) < 1e-12          # a lattice point at the centre
    np.testing.assert_array_equal(sim.v[k], v0)
    # and the profile along the x axis: v = v0 exp(-s^2 / (2 sigma^2))
    ax = np.flatnonzero(np.linalg.norm(sim.points.x[:n, 1:], axis=1) < 1e-12)
    assert len(ax) == 37
    s = sim.points.x[ax, 0]
    np.testing.assert_allclose(sim.v[ax], np.exp(-0.5 * s ** 2 / sigma ** 2)[:, None] * v0,
                               rtol=1e-14, atol=0)


@pytest.mark.parametrize("sigma", [0.0, -1e-3])
def test_gaussian_velocity_needs_positive_sigma(sigma):
    with pytest.raises(SceneError, match=r"^initial\.0\.sigma: must be > 0"):
        make_scene(gaussian_scene(sigma=sigma))
