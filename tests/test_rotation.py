"""Rotation and objectivity.

1. Along a prescribed history F(t) = Q(t) U(t) (a stretch that grows while the
   body turns), the Flanagan–Taylor update keeps V R = F and R orthogonal.
2. A large rigid rotation of a block, prescribed step by step through the
   solver's update, produces no stress and no internal force, to round-off.
"""
import numpy as np
import pytest
from conftest import make_scene, scene_dict

from mpipd.kernels.rotation import rotate_stretch
from mpipd.solver import Simulation


def rot(axis, angle):
    a = np.asarray(axis, float) / np.linalg.norm(axis)
    K = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    return np.eye(3) + np.sin(angle) * K + (1 - np.cos(angle)) * K @ K


def history(t):
    U = np.eye(3) + t * np.array([[0.3, 0.05, 0.0], [0.05, -0.1, 0.02], [0.0, 0.02, 0.2]])
    return rot([1, 2, 3], 1.2 * t) @ U


def simple_shear(t):
    return np.array([[1.0, 1.5 * t, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]])


@pytest.mark.parametrize("hist,tol", [(history, 2e-4), (simple_shear, 1e-3)])
def test_polar_update_tracks_F(hist, tol):
    n_steps = 2000
    dt = 1.0 / n_steps
    F_old = hist(0.0)[None].copy()
    R = np.eye(3)[None].copy()
    V = np.eye(3)[None].copy()
    d = np.zeros((1, 6))
    J = np.ones(1)
    spring = np.zeros(1, np.uint8)
    for k in range(n_steps):
        F_new = hist((k + 1) * dt)[None].copy()
        Fdot = (F_new - F_old) / dt
        rotate_stretch(F_old, F_new, Fdot, R, V, dt, spring, d, J, np.ones_like(J), np.ones_like(J),
                       np.zeros(1, np.uint8), 0, np.zeros(1, np.uint8))
        F_old = F_new
        # V stays symmetric to round-off only with the right sign of the correction
        assert np.abs(V[0] - V[0].T).max() < 1e-12
    F = hist(1.0)
    np.testing.assert_allclose(V[0] @ R[0], F, atol=tol)
    np.testing.assert_allclose(R[0] @ R[0].T, np.eye(3), atol=1e-12)
    # and R is the rotation of the polar decomposition of F
    u, s, vt = np.linalg.svd(F)
    np.testing.assert_allclose(R[0], u @ vt, atol=tol)


def test_rigid_rotation_is_stress_free(team):
    lo, hi = [-0.006, -0.005, -0.004], [0.006, 0.005, 0.004]
    sim = Simulation(make_scene(scene_dict({"kind": "box", "lo": lo, "hi": hi}, dx=1e-3)), team)
    X = sim.points.x
    axis = [0.3, -0.5, 0.8]
    total, n_steps, dt = np.radians(60.0), 600, 1e-7
    u_prev = sim.u.copy()
    for k in range(1, n_steps + 1):
        Q = rot(axis, total * k / n_steps)
        u_new = X @ Q.T - X
        sim.v[:] = (u_new - u_prev) / dt        # what velocity Verlet would carry
        sim.u[:] = u_new
        sim.update(dt)
        u_prev = u_new
    K = 21.9e9
    assert np.abs(sim.corr.sigma).max() < 1e-6 * K * 1e-6     # < 1e-6 Pa
    dx = 1e-3
    assert np.abs(sim.f).max() < 1e-9 * K / dx
    # the rotation was really applied: R follows Q
    np.testing.assert_allclose(sim.corr.R[0], rot(axis, total), atol=1e-6)
    np.testing.assert_allclose(sim.corr.V[0], np.eye(3), atol=1e-9)
