"""Independent checks of the force assembly.

* With P held fixed, the internal force is the exact gradient of
  Phi(u) = sum_i V_i P_i : F_i(u), and the hourglass force of E_hg(u):
  f_k V_k = -dPhi/du_k.  Finite differences catch any wrong transpose or sign
  in P, K^-1 or the gather (a uniform-stress patch test cannot).
* Newton's third law: sum_i f_i V_i = 0 for any u and stress, also across parts
  with different lattice spacings and horizons (dual horizons).

These check the dual-horizon assembly alone; the interface correction, which
is neither, has its own tests (test_interface.py).
"""
import numpy as np
from conftest import granite, make_scene, scene_dict

from mpipd.solver import Simulation


def two_parts(hourglass):
    parts = [{"name": "coarse", "material": "a", "dx": 1e-3,
              "shape": {"kind": "box", "lo": [0, 0, 0], "hi": [0.006, 0.006, 0.006]}},
             {"name": "fine", "material": "b", "dx": 0.5e-3, "horizon_factor": 2.5,
              "shape": {"kind": "box", "lo": [0.006, 0, 0], "hi": [0.009, 0.006, 0.006]}}]
    d = scene_dict(None, parts=parts, hourglass=hourglass)
    d["materials"] = {"a": granite(), "b": granite(shear_modulus=40e9, density=8000.0)}
    d["solver"]["interface_correction"] = False     # the dual-horizon assembly itself
    return make_scene(d)


def randomize(sim, rng, scale=1e-6):
    n = sim.points.n_owned
    sim.u[:] = rng.normal(size=sim.u.shape) * scale
    sim.corr.sigma[:] = rng.normal(size=(n, 6)) * 1e7
    sim.corr.R[:] = np.eye(3)


def test_net_internal_force_vanishes_across_horizons(team):
    rng = np.random.default_rng(3)
    sim = Simulation(two_parts(hourglass=0.05), team)
    randomize(sim, rng)
    sim.corr.deform(sim.u, sim.v)
    sim.compute_forces()
    V = sim.points.volume[:sim.points.n_owned]
    net = (sim.f * V[:, None]).sum(axis=0)
    scale = (np.abs(sim.f) * V[:, None]).sum()
    assert np.abs(net).max() < 1e-12 * scale


def test_force_is_gradient_of_energy_with_fixed_stress(team):
    rng = np.random.default_rng(4)
    sim = Simulation(two_parts(hourglass=0.05), team)
    randomize(sim, rng)
    p = sim.points
    n = p.n_owned
    c = sim.corr
    c.deform(sim.u, sim.v)
    sim.compute_forces()
    # P held fixed at the current state
    F0 = c.F.copy()
    S = np.zeros((n, 3, 3))
    s = c.sigma
    S[:, 0, 0], S[:, 1, 1], S[:, 2, 2] = s[:, 0], s[:, 1], s[:, 2]
    S[:, 1, 2] = S[:, 2, 1] = s[:, 3]
    S[:, 0, 2] = S[:, 2, 0] = s[:, 4]
    S[:, 0, 1] = S[:, 1, 0] = s[:, 5]
    J = np.linalg.det(F0)
    P = J[:, None, None] * S @ np.linalg.inv(F0).transpose(0, 2, 1)
    V = p.volume[:n]

    def phi(u):
        c.deform(u, sim.v)
        return float(np.sum(V * np.einsum("nij,nij->n", P, c.F))) + c.hourglass_energy(u)

    h = 1e-10
    for k in rng.choice(n, 8, replace=False):
        for a in range(3):
            up, um = sim.u.copy(), sim.u.copy()
            up[k, a] += h
            um[k, a] -= h
            grad = (phi(up) - phi(um)) / (2 * h)
            assert abs(sim.f[k, a] * V[k] + grad) <= 1e-5 * abs(grad) + 1e-9
