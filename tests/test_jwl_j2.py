"""JWL equation of state (Eq. 48, Table 2) and the copper's J2 plasticity."""
import math

import numpy as np
import pytest

from mpipd.materials.j2 import J2
from mpipd.materials.jwl import JWL

G = JWL()


def test_pressure_at_initial_density_is_closed_form():
    A, B, R1, R2, w, e0 = 568e9, 21.6e9, 5.81, 1.77, 0.282, 7.38e9
    want = A * (1 - w / R1) * math.exp(-R1) + B * (1 - w / R2) * math.exp(-R2) + w * e0
    assert G.pressure(1.0, e0) == pytest.approx(want, rel=1e-14)
    assert 6.7e9 < want < 6.9e9                      # the constant-volume explosion pressure


def test_chapman_jouguet_speed_matches_vod():
    cj = G.chapman_jouguet()
    assert abs(cj["D"] - 6690.0) / 6690.0 < 0.01
    # tangency: the Rayleigh line through CJ has the Hugoniot's slope there
    V, p = cj["V"], cj["p"]
    h = 1e-6
    slope = (G.hugoniot_pressure(V + h) - G.hugoniot_pressure(V - h)) / (2 * h)
    assert slope == pytest.approx(-G.density * cj["D"] ** 2, rel=1e-5)
    # the CJ state is on the EOS with the Hugoniot energy
    assert G.pressure(V, cj["e"]) == pytest.approx(p, rel=1e-12)
    assert 14e9 < p < 17e9


def test_pressure_along_the_isentrope_from_cj():
    """Integrate de = -p(V, e) dV from CJ with the EOS (RK4) and compare with the
    closed-form isentrope A e^-R1V + B e^-R2V + C V^-(1+w)."""
    cj = G.chapman_jouguet()
    C = G.isentrope_constant(cj["V"], cj["p"])
    V, e = cj["V"], cj["e"]
    n = 4000
    h = (7.0 - V) / n
    for _ in range(n):
        k1 = -G.pressure(V, e)
        k2 = -G.pressure(V + h / 2, e + h / 2 * k1)
        k3 = -G.pressure(V + h / 2, e + h / 2 * k2)
        k4 = -G.pressure(V + h, e + h * k3)
        e += h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        V += h
    assert G.pressure(V, e) == pytest.approx(G.isentrope_pressure(V, C), rel=1e-8)


def j2_shear(gdot=1000.0, dt=1e-8, steps=6000, unload_at=None):
    m = J2()
    sigma = np.zeros((1, 6))
    mode = np.zeros(1, np.uint8)
    st = m.new_state(1)
    idx = np.zeros(1, np.int64)
    taus = []
    for k in range(steps):
        g = -gdot if (unload_at is not None and k >= unload_at) else gdot
        m.update(idx, np.array([[1e-3 * gdot, 0, 0, 0, 0, g]]), np.ones(1), dt, sigma, mode, st)
        taus.append(sigma[0, 5])
    return np.array(taus), sigma, st


def test_j2_yields_at_yield_stress_and_unloads_elastically():
    taus, sigma, st = j2_shear()
    s = sigma[0]
    dev = s[:3] - s[:3].mean()
    seq = math.sqrt(1.5 * (dev @ dev + 2 * (s[3:] @ s[3:])))
    assert seq == pytest.approx(450e6, rel=1e-12)                  # on the yield surface
    assert taus.max() == pytest.approx(450e6 / math.sqrt(3.0), rel=1e-4)   # ~pure shear
    assert taus[0] == pytest.approx(2 * 45e9 * 1000.0 * 1e-8)      # elastic slope 2 G
    assert st["eps_p"][0] > 0
    # the volumetric part stays elastic: p = K tr(eps), tr(eps) = 1e-3 * gdot * t
    tr = 1e-3 * 1000.0 * 1e-8 * 6000
    assert sigma[0, :3].mean() == pytest.approx(130e9 * tr, rel=1e-9)
    taus, _, _ = j2_shear(steps=6000, unload_at=5000)
    assert taus[5001] - taus[5000] == pytest.approx(-2 * 45e9 * 1000.0 * 1e-8, rel=1e-9)
