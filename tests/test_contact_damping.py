"""Contact (Eq. 40), damping of fully damaged points (Eq. 41), and energy with
viscosity and damping."""
import numpy as np
import pytest
from conftest import granite, make_scene, scene_dict

from mpipd.input import scene as sc
from mpipd.solver import Simulation

NEVER = {"sigma_st": -1e15}        # a tension model that never triggers: failure machinery on


def block(hi, contact, damping=0.0, dt=5e-8, initial=()):
    d = scene_dict({"kind": "box", "lo": [0, 0, 0], "hi": hi}, dt=dt, initial=initial)
    d["materials"] = {"granite": granite(tension=NEVER)}
    d["solver"].update({"contact": contact, "damping": damping})
    return make_scene(d)


def cut(sim, x0):
    """Break every bond crossing the plane x = x0 (a pre-existing crack)."""
    p, fam = sim.points, sim.families
    i = np.repeat(np.arange(p.n_owned), np.diff(fam.offsets))
    left_i = p.x[i, 0] < x0
    left_j = p.x[fam.nbr, 0] < x0
    fam.broken[left_i != left_j] = 1
    sim.corr.rebuild_shape()


@pytest.mark.parametrize("contact", [True, False])
def test_halves_driven_together_do_not_interpenetrate(team, contact):
    L = 0.012
    sim = Simulation(block([L, 0.006, 0.006], contact), team)
    cut(sim, L / 2)
    n = sim.points.n_owned
    x = sim.points.x[:n]
    left = x[:, 0] < L / 2
    sim.v[:n][left, 0] = 20.0
    sim.v[:n][~left, 0] = -20.0
    sim.initialize()
    lf = np.flatnonzero(np.isclose(x[:, 0], L / 2 - 0.5e-3))     # faces across the cut
    rf = np.flatnonzero(np.isclose(x[:, 0], L / 2 + 0.5e-3))
    lf = lf[np.lexsort((x[lf, 2], x[lf, 1]))]
    rf = rf[np.lexsort((x[rf, 2], x[rf, 1]))]
    gap = []
    for _ in range(700):                       # 35 us: free flight would close 1 mm in 25 us
        sim.step()
        gap.append((x[rf, 0] + sim.u[rf, 0] - x[lf, 0] - sim.u[lf, 0]).min())
    if contact:
        assert min(gap) > 0.2e-3               # they never meet
        assert sim.v[:n][left, 0].mean() < 0   # ... and bounce back
    else:
        assert min(gap) < 0                    # without contact they pass through


@pytest.mark.parametrize("contact", [True, False])
def test_fully_failed_region_carries_compression(team, contact):
    sim = Simulation(block([0.030, 0.006, 0.006], contact), team)
    n = sim.points.n_owned
    x = sim.points.x[:n]
    mid = (x[:, 0] > 0.010) & (x[:, 0] < 0.020)
    sim.failure.mode[:n][mid] = 1               # crushed: every bond of the region breaks
    sim.failure.update(sim.u)
    assert np.all(sim.failure.phi[mid] == 1.0)
    left, right = x[:, 0] < 0.010, x[:, 0] > 0.020
    sim.v[:n][left, 0] = 10.0
    sim.initialize()
    for _ in range(500):
        sim.step()
    p_right = sim.v[:n][right, 0].sum()
    p_left0 = 10.0 * left.sum()
    if contact:
        assert p_right > 0.05 * p_left0        # momentum got through the crushed zone
    else:
        assert abs(p_right) < 1e-12 * p_left0    # round-off only


def test_damping_of_fully_damaged_points_follows_eq41(team):
    c, dt = 2e5, 5e-8
    sim = Simulation(block([0.005, 0.005, 0.005], contact=False, damping=c, dt=dt), team)
    n = sim.points.n_owned
    sim.failure.mode[:n] = 1
    sim.failure.update(sim.u)
    assert np.all(sim.failure.damp == c)
    sim.v[:n] = [3.0, -1.0, 2.0]
    sim.initialize()
    steps = 300
    for _ in range(steps):
        sim.step()
    factor = ((2 - c * dt) / (2 + c * dt)) ** steps
    np.testing.assert_allclose(sim.v[:n], np.tile([3.0, -1.0, 2.0], (n, 1)) * factor, rtol=1e-12)


def test_energy_never_exceeds_input_with_viscosity_and_damping(team):
    scene, _ = sc.load("granite_ring", ["parts.0.dx=0.0015", "time.t_end=8e-6"])
    sim = Simulation(scene, team)
    e0 = sim.energies().total                 # the input: the initial kinetic energy
    totals = []
    for _ in range(scene.time.n_steps):
        sim.step()
        if sim.step_count % 10 == 0:
            totals.append(sim.energies().total)
    assert sim.failure.counts()[1:].sum() > 0            # it really fractured
    assert max(totals) <= e0 * (1 + 1e-6)
    assert totals[-1] < 0.9 * e0                          # and dissipated
