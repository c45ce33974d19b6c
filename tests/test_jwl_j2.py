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


@pytest.mark.parametrize("eta", [0.0, 1.0 / 3.0, -1.0 / 3.0, 2.0 / 3.0])
def test_johnson_cook_damage_fails_at_the_closed_form_strain(eta):
    """Pure shear at a constant rate g on a point held at the mean stress eta sigma_y
    (tr d = 0 keeps it): after yield every step adds deps_p = (2 g / sqrt 3) dt at
    the triaxiality eta, so the point fails (mode 4, stress zeroed) once eps_p
    passes eps_f = (d1 + d2 exp(d3 eta)) (1 + d4 ln(2 g / sqrt 3 / rate0)) —
    Johnson & Cook (1985), computed here, within the one step that crosses it."""
    from mpipd.kernels.layout import MODE_DUCTILE
    from mpipd.materials.ductile import DuctileFailure
    jc = DuctileFailure()
    m = J2(failure=jc)
    g, dt = 2.0e4, 1e-8
    rate = 2.0 * g / math.sqrt(3.0)
    ef = (jc.d1 + jc.d2 * math.exp(jc.d3 * eta)) * (1.0 + jc.d4 * math.log(rate / jc.rate0))
    sigma = np.zeros((1, 6))
    sigma[0, :3] = eta * m.yield_stress
    mode = np.zeros(1, np.uint8)
    st = m.new_state(1)
    idx = np.zeros(1, np.int64)
    d = np.array([[0.0, 0, 0, 0, 0, g]])
    steps = 0
    while mode[0] == 0 and steps < 10 ** 6:
        m.update(idx, d, np.ones(1), dt, sigma, mode, st)
        steps += 1
    assert mode[0] == MODE_DUCTILE and np.all(sigma[0] == 0.0) and st["D_jc"][0] == 1.0
    # the elastic shear strain before yield (sigma_y / sqrt 3 / 2G) carries no damage
    assert st["eps_p"][0] == pytest.approx(ef, abs=rate * dt * 1.01)
    # without the failure model the same path never fails
    m0, mode0, st0, s0 = J2(), np.zeros(1, np.uint8), J2().new_state(1), np.zeros((1, 6))
    for _ in range(steps + 100):
        m0.update(idx, d, np.ones(1), dt, s0, mode0, st0)
    assert mode0[0] == 0 and "D_jc" not in st0 and not m0.can_fail and m.can_fail


def test_johnson_cook_damage_refuses_bad_constants():
    from mpipd.input import scene as sc
    from mpipd.input.schema import SceneError
    for bad, key in (("{rate0=0}", "rate0"), ("{d1=-5.0}", "d1"), ("{e1=1}", "e1")):
        with pytest.raises(SceneError, match=f"materials.copper.failure.{key}"):
            sc.load("blast_demo", [f"materials.copper.failure={bad}"])
