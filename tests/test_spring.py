"""Bond-spring fallback: two points cannot form an invertible shape tensor, so
both act as bond-based springs, f = c s Y/|Y| V_j with c = 18 K / (pi delta^4)."""
import math

import numpy as np
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
