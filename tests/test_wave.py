"""elastic_wave: P-wave arrival speed and energy conservation.

The expected speeds are computed here from the granite constants, not taken
from the code: 1-D strain c_p = sqrt((K + 4G/3)/rho), bar c_0 = sqrt(E/rho).
The run is the built-in scene at dx = 2 mm with a 160 mm pulse (kept long
against the 6 mm horizon so peridynamic dispersion stays small).
"""
import math

import numpy as np
import pytest

from mpipd.input import scene as sc
from mpipd.solver import Simulation

RHO, K, G = 2660.0, 21.9e9, 25.7e9
C_P = math.sqrt((K + 4 * G / 3) / RHO)
C_BAR = math.sqrt(9 * K * G / (3 * K + G) / RHO)
STATIONS = (0.08, 0.12, 0.16)


@pytest.fixture(scope="module", params=[0.0, 0.2], ids=["lattice", "jitter0.2"])
def wave(team, request):
    """The wave on the cubic lattice and on a lattice jittered by 0.2 dx (the rock
    mass's irregular families: mpipd.input.geometry)."""
    over = ["parts.0.dx=0.002", "time.dt=2e-7", "time.t_end=4.4e-5", "initial.0.half_width=0.04",
            f"parts.0.jitter={request.param}"]
    scene, _ = sc.load("elastic_wave", over)
    sim = Simulation(scene, team)
    n = sim.points.n_owned
    x = sim.points.x[:n, 0]
    masks = [np.abs(x - s) < 1e-3 + 1e-9 for s in STATIONS]
    t, vx, energy = [0.0], [[0.0] * len(STATIONS)], [sim.energies().total]
    for _ in range(scene.time.n_steps):
        sim.step()
        t.append(sim.t)
        vx.append([sim.v[:n][m, 0].mean() for m in masks])
        if sim.step_count % 10 == 0:
            energy.append(sim.energies().total)
    return np.array(t), np.array(vx), np.array(energy)


def peak_time(t, y):
    k = int(np.argmax(y))
    y0, y1, y2 = y[k - 1:k + 2]
    return t[k] + 0.5 * (y0 - y2) / (y0 - 2 * y1 + y2) * (t[1] - t[0])


def test_p_wave_speed(wave):
    t, vx, _ = wave
    arrivals = [peak_time(t, vx[:, k]) for k in range(len(STATIONS))]
    speed = np.polyfit(arrivals, STATIONS, 1)[0]
    assert abs(speed - C_P) / C_P < 0.03, (speed, C_P)
    assert abs(speed - C_BAR) / C_BAR < 0.03, (speed, C_BAR)
    # the pulse carries peak velocity 1/2 of the initial bump (half of a symmetric bump)
    assert 0.4 < vx[:, 0].max() < 0.55


def test_energy_conserved(wave):
    _, _, energy = wave
    assert energy[0] > 0
    assert np.abs(energy - energy[0]).max() < 0.01 * energy[0]
