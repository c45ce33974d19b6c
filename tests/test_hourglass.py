"""Hourglass control (Eq. 15 with a modulus, see mpipd.kernels.nosb).

* A checkerboard displacement is a zero-energy mode of the correspondence
  model: with no penalty, interior points feel no force at all.
* With the penalty it is resisted: it oscillates, its amplitude stays bounded
  by the initial one, and total energy is conserved.
* Smooth fields are unaffected: an affine field feels no penalty anywhere, and a
  smooth wave run with and without the penalty gives the same velocities.
"""
import numpy as np
from conftest import make_scene, scene_dict

from mpipd.input import scene as sc
from mpipd.solver import Simulation

BOX = {"kind": "box", "lo": [0, 0, 0], "hi": [0.014, 0.014, 0.014]}
A = 1e-6                                        # checkerboard amplitude (m)


def checkerboard(sim):
    k = np.rint(sim.points.x / 1e-3 - 0.5).astype(int)
    sign = np.where(k.sum(axis=1) % 2 == 0, 1.0, -1.0)
    sim.u[:] = A * sign[:, None] * np.array([1.0, 1.0, 1.0]) / np.sqrt(3.0)
    sim.initialize()
    return sign


def deep(sim, margin):
    n = sim.points.n_owned
    x = sim.points.x[:n]
    return np.all((x > margin) & (x < 0.014 - margin), axis=1)


def test_checkerboard_is_zero_energy_without_penalty(team):
    sim = Simulation(make_scene(scene_dict(BOX, hourglass=0.0)), team)
    checkerboard(sim)
    # F = I exactly in the interior: the mode is invisible to the correspondence force
    inner = deep(sim, sim.points.horizon[0])
    np.testing.assert_allclose(sim.corr.F[inner], np.broadcast_to(np.eye(3), (inner.sum(), 3, 3)),
                               atol=1e-15)
    for _ in range(20):
        sim.step()
    d2 = deep(sim, 2 * sim.points.horizon[0])
    assert np.abs(sim.f[d2]).max() == 0.0


def test_checkerboard_stays_bounded_with_penalty(team):
    sim = Simulation(make_scene(scene_dict(BOX, hourglass=0.01, dt=5e-8)), team)
    sign = checkerboard(sim)
    e0 = sim.energies()
    assert e0.hourglass > 0.0 and e0.kinetic == 0.0
    n = sim.points.n_owned
    inner = deep(sim, sim.points.horizon[0])
    amp, totals = [], []
    for k in range(1200):
        sim.step()
        if k % 20 == 0:
            proj = (sim.u[:n][inner] @ (np.ones(3) / np.sqrt(3.0))) * sign[:n][inner]
            amp.append(proj.mean())
            totals.append(sim.energies().total)
    amp = np.array(amp)
    assert np.abs(sim.u[:n]).max() < 2.0 * A                # bounded
    assert amp.min() < 0.0                                   # restored: it swings through zero
    totals = np.array(totals)
    assert np.abs(totals - e0.total).max() < 0.01 * e0.total


def test_affine_field_feels_no_penalty(team):
    sim = Simulation(make_scene(scene_dict(BOX, hourglass=0.05)), team)
    H = np.array([[2e-3, 1e-3, 0], [0, -1e-3, 5e-4], [1e-4, 0, 3e-3]])
    sim.u[:] = sim.points.x @ H.T
    sim.initialize()                  # stress is zero, so any force is the penalty's
    assert np.abs(sim.f).max() < 1e-12 * 25.7e9 * 0.05 * np.abs(H).max() / 1e-3
    assert sim.energies().hourglass < 1e-20


def test_smooth_wave_unchanged_by_penalty(team):
    over = ["parts.0.dx=0.002", "time.dt=2e-7", "time.t_end=1.6e-5",
            "initial.0.half_width=0.04"]
    runs = {}
    for c in (0.0, 0.01):
        scene, _ = sc.load("elastic_wave", over + [f"solver.hourglass={c}"])
        sim = Simulation(scene, team)
        for _ in range(scene.time.n_steps):
            sim.step()
        runs[c] = sim
    v0 = runs[0.0].v[:runs[0.0].points.n_owned]
    v1 = runs[0.01].v[:runs[0.01].points.n_owned]
    assert np.linalg.norm(v1 - v0) < 0.01 * np.linalg.norm(v0)
    e = runs[0.01].energies()
    assert e.hourglass < 1e-3 * e.total
