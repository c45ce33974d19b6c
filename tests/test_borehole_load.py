"""Borehole pressure load: the force it applies, the wave it drives, and the
energy balance with the work it does."""
import math

import numpy as np
import pytest
from conftest import make_scene, run_cli, scene_dict

from mpipd.input.loads import BoreholePressure
from mpipd.input.schema import SceneError, build
from mpipd.solver import Simulation

R, H, P = 0.020, 0.005, 1e8     # H: the mid-plane sits two lattice layers from the free faces


def ring(load):
    shape = {"kind": "annulus", "center": [0, 0], "inner_radius": R, "radius": 0.040, "z": [0, H]}
    d = scene_dict(shape, dx=1e-3, dt=5e-8)
    d["loads"] = [load]
    return make_scene(d)


def test_pulse_and_table_histories():
    pulse = build(BoreholePressure, {"center": [0, 0], "radius": R, "p0": 2e9,
                                     "alpha": 1e5, "beta": 1e6})
    t = 3e-6
    assert pulse.value(t) == pytest.approx(2e9 * (math.exp(-0.3) - math.exp(-3.0)))
    table = build(BoreholePressure, {"center": [0, 0], "radius": R, "times": [0, 1e-6, 2e-6],
                                     "pressures": [0, 1e8, 5e7]})
    assert table.value(0.5e-6) == pytest.approx(5e7)
    assert table.value(1.5e-6) == pytest.approx(7.5e7)
    assert table.value(9.0) == pytest.approx(5e7)
    for bad in ({"p0": 1e9, "alpha": 1e6, "beta": 1e5},                 # beta <= alpha
                {"p0": 1e9, "alpha": 1e5, "beta": 1e6, "times": [0, 1]},  # both forms
                {"times": [0, 1], "pressures": [0]},
                {"times": [1, 0], "pressures": [0, 1]}):
        with pytest.raises(SceneError):
            build(BoreholePressure, {"center": [0, 0], "radius": R, **bad})


def test_wall_pressure_wave_and_energy_balance(team):
    load = {"kind": "borehole_pressure", "center": [0, 0], "radius": R,
            "times": [0, 2e-6, 1.0], "pressures": [0, P, P]}
    sim = Simulation(ring(load), team)
    pl = sim.loads[0]
    V = sim.points.volume[pl.idx]
    # total radial force = p * wall area (2 pi R H), exactly
    radial = np.sum(V * np.hypot(pl.g[:, 0], pl.g[:, 1]))
    assert radial == pytest.approx(2 * math.pi * R * H, rel=1e-12)
    n = sim.points.n_owned
    x = sim.points.x[:n]
    r = np.hypot(x[:, 0], x[:, 1])
    er = x[:, :2] / r[:, None]
    wall = (r < R + 1e-3) & (np.abs(x[:, 2] - H / 2) < 0.6e-3)
    peak = 0.0
    for _ in range(200):                            # 10 us: the wave is 46 mm out
        sim.step()
        s = sim.corr.cauchy_stress()
        srr = s[:, 0] * er[:, 0] ** 2 + s[:, 1] * er[:, 1] ** 2 + 2 * s[:, 5] * er[:, 0] * er[:, 1]
        peak = min(peak, srr[wall].mean())
    assert abs(-peak - P) / P < 0.03               # the wall carries the applied pressure
    e = sim.energies()
    assert e.external > 0
    assert abs(e.total - e.external) < 1e-3 * e.external   # all the work went into the rock


def test_bad_load_in_a_scene_is_a_clear_error(tmp_path):
    res = run_cli(["check", "granite_ring", "--set",
                   'loads=[{kind="borehole_pressure", center=[0,0], radius=0.0032, p0=1e9}]'])
    assert res.returncode == 2 and "loads.0" in res.stderr and "either" in res.stderr


def test_radial_velocity_equals_the_impulse_matched_pressure(team):
    """An initial radial velocity v0 in a shell of width w at a free borehole wall
    launches (1-D theory) the same outgoing wave as a wall pressure
    p = rho c_p v0 / 2 held for 2 w / c_p: half the shell's velocity runs out at
    once, the other half reflects off the free wall and follows.  The two loads'
    peak radial stresses 6.5 mm out must agree within a few per cent."""
    rho, c = 2660.0, math.sqrt((21.9e9 + 4 * 25.7e9 / 3) / 2660.0)
    v0, w = 20.0, 2.0e-3
    p, T = rho * c * v0 / 2, 2 * w / c

    def peak(**extra):
        shape = {"kind": "annulus", "center": [0, 0], "inner_radius": R, "radius": 0.032,
                 "z": [0, H]}
        d = scene_dict(shape, dx=1e-3, dt=5e-8)
        d.update(extra)
        sim = Simulation(make_scene(d), team)
        n = sim.points.n_owned
        x = sim.points.x[:n]
        r = np.hypot(x[:, 0], x[:, 1])
        er = x[:, :2] / r[:, None]
        sel = (np.abs(r - R - 6.5e-3) < 0.5e-3) & (np.abs(x[:, 2] - H / 2) < 0.6e-3)
        pk = 0.0
        for _ in range(110):
            sim.step()
            s = sim.corr.cauchy_stress()[sel]
            e = er[sel]
            srr = s[:, 0] * e[:, 0] ** 2 + s[:, 1] * e[:, 1] ** 2 + 2 * s[:, 5] * e[:, 0] * e[:, 1]
            pk = min(pk, srr.mean())
        return -pk

    by_velocity = peak(initial=[{"kind": "radial_velocity", "center": [0, 0], "r_inner": 0.0,
                                 "r_outer": R + w, "speed": v0}])
    by_pressure = peak(loads=[{"kind": "borehole_pressure", "center": [0, 0], "radius": R,
                               "times": [0, T, T + 1e-9, 1.0], "pressures": [p, p, 0, 0]}])
    assert by_velocity > 0.3 * p                    # a real wave arrived
    assert by_velocity == pytest.approx(by_pressure, rel=0.07)
