"""Initial and boundary conditions, and the scene commands."""
import numpy as np
from conftest import make_scene, run_cli, scene_dict

from mpipd import scene as sc
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
