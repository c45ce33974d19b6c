"""A single-point driver over every registered correspondence material.

Each material of :data:`mpipd.materials.MATERIALS` whose points are the
total-Lagrangian solids (``family == "tl"``) is driven here through
``new_state`` / ``update`` / ``elastic_energy`` alone, the way the
correspondence machinery calls it, along strain paths whose small-strain answers
are computed in the test (isotropic linear elasticity, K = ``bulk_modulus``,
G = ``shear_modulus``).  A newly registered material is picked up
automatically; one whose required parameters this driver cannot fill fails
with a message naming them.  A material with a choice of law (:data:`CHOICES`:
JH2's ``pressure``, "eos" or "incremental") is driven under each choice.
"""
import dataclasses

import numpy as np
import pytest

from mpipd.input.schema import build
from mpipd.materials import MATERIALS
from mpipd.materials.jh2 import PRESSURES

#: values for parameters a material requires (no default): a granite-like solid
REQUIRED = {"density": 2660.0, "bulk_modulus": 21.9e9, "shear_modulus": 25.7e9}

SOLIDS = [n for n in MATERIALS.names() if MATERIALS.get(n).family == "tl"]

#: a material with a choice of law is driven once per choice (its settings here);
#: every other solid once, with its defaults
CHOICES = {"jh2": [{"pressure": p} for p in PRESSURES]}

CASES = [pytest.param(n, o, id="-".join([n, *map(str, o.values())]))
         for n in SOLIDS for o in CHOICES.get(n, [{}])]


def make(name, options=None):
    cls = MATERIALS.get(name)
    need = [f.name for f in dataclasses.fields(cls)
            if f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING]
    missing = [k for k in need if k not in REQUIRED]
    if missing:
        pytest.fail(f"material {name!r} requires {missing}: give the driver values for them")
    return build(cls, {**{k: REQUIRED[k] for k in need}, **(options or {})}, f"materials.{name}")


def drive(mat, d_rate, t_total, steps=200, n=1, mode=None):
    """Drive n identical points with a constant unrotated rate d (Voigt, tensor shear
    components) for t_total; J = exp(tr(d) t).  Returns (sigma, W, state, mode), W
    the stress work per reference volume by the midpoint rule, computed here."""
    dt = t_total / steps
    d = np.tile(np.asarray(d_rate, float), (n, 1))
    sigma = np.zeros((n, 6))
    mode = np.zeros(n, np.uint8) if mode is None else mode
    state = mat.new_state(n)
    idx = np.arange(n, dtype=np.int64)
    W = np.zeros(n)
    trd = float(d[0, :3].sum())
    wgt = np.array([1, 1, 1, 2, 2, 2], float)          # s:d in Voigt with tensor shears
    for k in range(steps):
        J_end = np.full(n, np.exp(trd * (k + 1) * dt))
        J_mid = np.exp(trd * (k + 0.5) * dt)
        before = sigma.copy()
        mat.update(idx, d, J_end, dt, sigma, mode, state)
        W += J_mid * dt * ((0.5 * (before + sigma) * d) @ wgt)
    return sigma, W, state, mode, J_end


def linear(mat):
    K, G = mat.bulk_modulus, mat.shear_modulus
    return K, G, K + 4.0 * G / 3.0, K - 2.0 * G / 3.0


def test_every_solid_is_driven():
    """The registry's solids are this driver's parameters (the explosive is the
    updated-Lagrangian gas, tests/test_gas.py)."""
    assert {"elastic", "j2", "jh2"} <= set(SOLIDS)
    assert all(MATERIALS.get(n).family in ("tl", "ul") for n in MATERIALS.names())
    assert set(CHOICES) <= set(SOLIDS)
    assert [c.values[1]["pressure"] for c in CASES if c.values[0] == "jh2"] == ["eos", "incremental"]


@pytest.mark.parametrize("name,options", CASES)
def test_state_arrays_have_one_row_per_point(name, options):
    mat = make(name, options)
    for n in (0, 1, 7):
        for key, arr in mat.new_state(n).items():
            assert arr.shape[0] == n, key


@pytest.mark.parametrize("name,options", CASES)
def test_no_rate_no_stress(name, options):
    sigma, W, _, mode, _ = drive(make(name, options), np.zeros(6), 1e-6, steps=20)
    assert np.all(sigma == 0.0) and np.all(W == 0.0) and np.all(mode == 0)


@pytest.mark.parametrize("name,options", CASES)
def test_uniaxial_strain_small(name, options):
    """Compression to eps = -1e-6 in 1-D strain: sigma_xx = (K + 4G/3) eps,
    sigma_yy = sigma_zz = (K - 2G/3) eps, no shear, no failure; the recoverable
    energy is (K + 4G/3) eps^2 / 2 (within the EOS's higher-order terms)."""
    mat = make(name, options)
    eps, t = -1e-6, 1e-6
    sigma, W, state, mode, J = drive(mat, [eps / t, 0, 0, 0, 0, 0], t)
    K, G, M, lam = linear(mat)
    assert mode[0] == 0
    assert sigma[0, 0] == pytest.approx(M * eps, rel=2e-3)
    assert sigma[0, 1] == pytest.approx(lam * eps, rel=2e-3)
    assert sigma[0, 2] == pytest.approx(sigma[0, 1], rel=1e-12)
    assert np.all(sigma[0, 3:] == 0.0)
    out = np.zeros(1)
    mat.elastic_energy(np.arange(1), sigma, J, mode, state, W, out)
    assert out[0] == pytest.approx(0.5 * M * eps * eps, rel=5e-3)
    assert W[0] == pytest.approx(0.5 * M * eps * eps, rel=5e-3)


@pytest.mark.parametrize("name,options", CASES)
def test_simple_shear_small(name, options):
    """A shear rate d_xy for a strain gamma/2 = 1e-6: sigma_xy = 2 G (gamma/2), no
    normal stress (isochoric, J = 1)."""
    mat = make(name, options)
    e, t = 1e-6, 1e-6
    sigma, _, _, mode, _ = drive(mat, [0, 0, 0, 0, 0, e / t], t)
    _, G, _, _ = linear(mat)
    assert mode[0] == 0
    assert sigma[0, 5] == pytest.approx(2.0 * G * e, rel=1e-9)
    assert np.abs(sigma[0, :5]).max() <= 1e-9 * abs(sigma[0, 5])


@pytest.mark.parametrize("name,options", CASES)
def test_isotropy(name, options):
    """Relabelling the axes of the rate relabels the stress."""
    mat = make(name, options)
    d = np.array([-3e-1, 1e-1, -0.5e-1, 0.2e-1, -0.4e-1, 0.7e-1])
    a = drive(mat, d, 1e-5, steps=50)[0][0]
    perm = [1, 2, 0]                          # x -> y -> z -> x: (yz, xz, xy) follow
    dp = np.concatenate([d[:3][perm], d[3:][perm]])
    b = drive(mat, dp, 1e-5, steps=50)[0][0]
    np.testing.assert_allclose(np.concatenate([a[:3][perm], a[3:][perm]]), b,
                               rtol=1e-12, atol=1e-9 * np.abs(a).max())


@pytest.mark.parametrize("name,options", CASES)
def test_failed_point_is_left_alone(name, options):
    """A point with mode != 0 keeps its (zero) stress and its mode."""
    mode = np.array([1, 0], np.uint8)
    sigma, _, _, mode, _ = drive(make(name, options), [-1.0, 0.5, 0, 0, 0, 0.3], 1e-6, n=2, mode=mode)
    assert np.all(sigma[0] == 0.0) and mode[0] == 1
    assert np.any(sigma[1] != 0.0)


@pytest.mark.parametrize("name,options", CASES)
def test_points_are_independent(name, options):
    """Each point's stress depends on its own rate only: two different rates side by
    side give what each gives alone."""
    mat = make(name, options)
    d = np.array([[-1.0, 0.5, 0, 0, 0, 0.3], [0.2, -0.1, -0.3, 0.1, 0, 0]])
    J_end = np.ones(2)
    idx = np.arange(2, dtype=np.int64)
    sigma, state, mode = np.zeros((2, 6)), mat.new_state(2), np.zeros(2, np.uint8)
    for _ in range(5):
        mat.update(idx, d, J_end, 1e-6, sigma, mode, state)
    for k in range(2):
        s1, st1, m1 = np.zeros((1, 6)), mat.new_state(1), np.zeros(1, np.uint8)
        for _ in range(5):
            mat.update(np.arange(1), d[k:k + 1], J_end[:1], 1e-6, s1, m1, st1)
        assert np.array_equal(s1[0], sigma[k])
