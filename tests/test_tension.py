"""Tension failure model (Eqs. 37–38) and the closed-form principal stresses."""
import math

import numpy as np
import pytest

from mpipd.materials.tension import (
    TensionFailure,
    dynamic_strength,
    principal_max_min,
    tension_check,
)


def test_principal_stresses_match_numpy():
    rng = np.random.default_rng(1)
    for _ in range(200):
        a = rng.normal(size=(3, 3)) * 10.0 ** rng.integers(-3, 9)
        a = a + a.T
        w = np.linalg.eigvalsh(a)
        hi, lo = principal_max_min(a[0, 0], a[1, 1], a[2, 2], a[1, 2], a[0, 2], a[0, 1])
        scale = np.abs(w).max()
        assert hi == pytest.approx(w[-1], abs=1e-9 * scale)
        assert lo == pytest.approx(w[0], abs=1e-9 * scale)
    assert principal_max_min(5.0, 5.0, 5.0, 0.0, 0.0, 0.0) == (5.0, 5.0)


@pytest.mark.parametrize("edot", [0.0, 0.1, 0.4, 0.41, 1.0, 10.0, 1e3, 1e4])
def test_dynamic_strength_eq38(edot):
    sst, c1, r0 = -6.9e6, 0.33, 0.4
    want = sst if edot <= r0 else sst * (edot / r0) ** c1
    assert dynamic_strength(edot, sst, c1, r0) == pytest.approx(want, rel=1e-13)


def uniaxial(s, edot):
    """A point under uniaxial tension s along a rotated axis, deforming at rate edot."""
    n = np.array([1.0, 2.0, 2.0]) / 3.0
    S = s * np.outer(n, n)
    sigma = np.array([[S[0, 0], S[1, 1], S[2, 2], S[1, 2], S[0, 2], S[0, 1]]])
    # pure deviatoric stretching with equivalent rate edot (Eq. 24): diag(e, -e/2, -e/2)
    d = np.array([[edot, -edot / 2, -edot / 2, 0.0, 0.0, 0.0]])
    return sigma, d


@pytest.mark.parametrize("edot", [0.1, 50.0, 2000.0])
@pytest.mark.parametrize("factor", [None, 0.6])
def test_point_fails_exactly_at_dynamic_strength(edot, factor):
    """Eq. 38 by hand: sigma_dt = (edot / edot_0)^C1 sigma_st above edot_0, times a
    heterogeneous point's strength factor."""
    model = TensionFailure()
    f = 1.0 if factor is None else factor
    limit = 6.9e6 * f * (edot / 0.4) ** 0.33 if edot > 0.4 else 6.9e6 * f   # tension-positive
    fac = np.ones(0) if factor is None else np.array([factor])
    for s, fails in ((limit * (1 - 1e-9), False), (limit * (1 + 1e-9), True)):
        sigma, d = uniaxial(s, edot)
        mode = np.zeros(1, np.uint8)
        n = tension_check(np.zeros(1, np.int64), sigma, d, mode, model.sigma_st, model.c1,
                          model.rate0, fac)
        assert (n == 1) == fails and (mode[0] == 3) == fails
        if fails:
            assert np.all(sigma == 0.0)
    # compression never fails it
    sigma, d = uniaxial(-10 * limit, edot)
    mode = np.zeros(1, np.uint8)
    assert tension_check(np.zeros(1, np.int64), sigma, d, mode, -6.9e6, 0.33, 0.4, fac) == 0


def test_rate_of_the_test_is_eq24():
    edot = 123.0
    _, d = uniaxial(1.0, edot)
    e = d[0]
    tr = e[:3].mean()
    dev = e[:3] - tr
    assert math.sqrt(2 / 3 * (dev @ dev)) == pytest.approx(edot)
