"""Johnson–Holmquist (JH2) ceramic/rock model (Johnson & Holmquist 1994; paper §2.2, Eqs. 19–36).

Sign convention.  mpipd stresses are tension-positive; JH2's pressure p is
compression-positive, so the Cauchy stress is sigma = S - p I with S the
deviator (the paper writes Eq. 35 as sigma = S + p I in a compression-positive
frame).

Per point and step, in the unrotated frame (d from Eq. 6, dt):

1. Pressure without bulking, p0, by the material's ``pressure`` choice:
   * ``"eos"`` (the default): Eq. 25 on the total compression
     mu = rho/rho0 - 1 = 1/J - 1 (J = det F at the end of the step),
         p0 = K1 mu + K2 mu^2 + K3 mu^3   (mu >= 0),   p0 = K1 mu   (mu < 0)
     (:func:`jh2_pressure`), as in JH2.  Table 1's cubic has a plateau at
     p ~ 34-35 MPa, with dp/dmu < 0 for mu in 0.0042..0.0058 (:meth:`JH2.negative_tangent`).
   * ``"incremental"``: Eq. 35's p_t = sigma'_v + dp_t, sigma'_v the hydrostatic
     part of the linear elastic trial stress of Eq. 19,
     sigma' = sigma + 2 G d dt + lambda I tr(d) dt, i.e. a history p_el
     (compression positive, 0 at the start) with
         p_el <- p_el - K1 tr(d) dt,   p0 = p_el,   K1 = lambda + 2G/3,
     so p_el = -K1 ln J on any path (tr d = d ln J / dt).  Eq. 25 does not enter
     (K1 is its bulk modulus; K2 and K3 are not used): the paper's Eq. 19 is
     linear, and its Eqs. 25/26 are the EOS form that its own Eq. 35 does not use.
     The paper's Figs. 14-15 (P1 yielding at p ~ 200 MPa with almost three times
     the unconfined strength) need a pressure that keeps rising linearly, which
     Table 1's cubic, with its plateau, does not give.
   Then p = p0 + dp (dp: the bulking pressure, step 6).
2. Tensile failure: p* = p / p_HEL < -T* (i.e. p < -T)  ->  the point fails (mode 2).
3. Trial deviator S' = S + 2 G dev(d) dt (Eq. 19), von Mises s = sqrt(3/2 S':S') (Eq. 20).
4. Strain rate (Eq. 24) edot = sqrt(2/3 dev(d):dev(d)), edot* = max(edot / edot_n, 1)
   (clamped so ln edot* >= 0).  Strengths (Eqs. 21–23):
       sigma_i* = A (p* + T*)^N (1 + C ln edot*),
       sigma_f* = B (p*)^M (1 + C ln edot*)  (0 for p* <= 0),
       sigma_y  = sigma_HEL [sigma_i* - D (sigma_i* - sigma_f*)],  sigma_HEL = 1.5 (HEL - p_HEL).
5. If s > sigma_y: radial return S = (sigma_y / s) S' (Eq. 31).  The plastic deviatoric
   strain increment (S' - S)/(2G) is parallel to S, so Eqs. 32–34 give
   deps_p = (s - sigma_y) / (3 G).  Damage (Eqs. 29–30):
       D += deps_p / eps_f,  eps_f = D1 (p* + T*)^D2;  D >= 1  ->  the point fails (mode 1).
6. Bulking (Eqs. 26–28): the strength lost to the damage step, at this p* and
   edot*, releases dU = [sigma_y(D_old)^2 - sigma_y(D_new)^2] / (6 G) > 0 and
       dp <- -p_lin + sqrt((p_lin + dp)^2 + 2 beta K1 dU),
   p_lin the linear elastic pressure: K1 mu under ``"eos"`` (Eq. 26 as printed),
   p_el under ``"incremental"`` — only where the point is in compression (p >= 0
   before the step).  Eq. 26 is the energy balance (p_new^2 - p_old^2) / (2 K1)
   = beta dU of a linear pressure, which raises |p|; applied literally in
   tension (p_lin + dp < 0) its positive root flips the sign of p (-44 MPa ->
   +44 MPa), i.e. turns a tensile point into a compressed one with no volume
   change.  Bulking is dilatancy of crushed material under compression (Johnson
   & Holmquist 1994), so in tension dp is left unchanged and dU is dissipated
   (the ledger's ``plastic``).  In compression p only grows, so no yield step
   changes its sign.
7. sigma = S - (p0 + dp) I (Eq. 35); the correspondence module rotates it (Eq. 36).

A failed point carries no stress; its bonds break (mpipd.model.failure).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property
from typing import NamedTuple

import numba
import numpy as np

from ..input.schema import fail, join, non_negative, positive, tagged
from ..kernels.layout import MODE_PLASTIC, MODE_TENSILE
from ..kernels.plasticity import deviatoric_rate, equivalent_rate, radial_return, trial_deviator, von_mises
from . import MATERIALS
from .base import Material
from .heterogeneity import DISTRIBUTIONS
from .tension import TensionFailure


@numba.njit(cache=True, inline="always")
def jh2_pressure(mu, K1, K2, K3):
    """Eq. 25 without the bulking term."""
    if mu >= 0.0:
        return K1 * mu + K2 * mu * mu + K3 * mu * mu * mu
    return K1 * mu


#: the choices of ``JH2.pressure`` (module docstring, step 1)
PRESSURES = ("eos", "incremental")

#: the ``p_el`` argument of the kernels under ``pressure = "eos"`` (not read)
NO_P_EL = np.zeros(0)

#: 8-point Gauss–Legendre nodes and weights on [-1, 1]
_GL_X, _GL_W = np.polynomial.legendre.leggauss(8)


@numba.njit(cache=True)
def eos_energy(mu, K1, K2, K3):
    """Energy per reference volume stored by the EOS (Eq. 25 without bulking) at
    compression mu: E = -int_1^J p dJ' = int_0^mu p(m) / (1 + m)^2 dm (J = 1/(1 + mu)),
    by 8-point Gauss–Legendre (the integrand is smooth on each branch; exact to
    round-off for |mu| < 0.3).  E >= 0: p has the sign of mu for Table 1."""
    h = 0.5 * mu
    e = 0.0
    for k in range(8):
        m = h * (1.0 + _GL_X[k])
        e += _GL_W[k] * jh2_pressure(m, K1, K2, K3) / ((1.0 + m) * (1.0 + m))
    return h * e


@numba.njit(cache=True)
def linear_volumetric_energy(p_el, K1):
    """Energy per reference volume stored by the linear hypoelastic pressure of
    Eq. 19 (``pressure = "incremental"``) at the elastic pressure p_el: with
    dp_el = -K1 d(ln J), p_el = -K1 ln J, and the stress work per reference
    volume, -p dJ, integrates to
        e_vol = -int_1^J p_el dJ' = K1 int_1^J ln J' dJ' = K1 (J ln J - J + 1)
              = K1 [1 - (1 + x) exp(-x)],   x = p_el / K1 = -ln J,
    >= 0 for either sign of x (1 + x <= exp(x)).  For |x| < 0.5 it is summed as
    the series K1 sum_{n>=2} (n - 1) (-x)^n / n! = K1 (x^2/2 - x^3/3 + x^4/8 - ...),
    which avoids the closed form's cancellation near x = 0."""
    x = p_el / K1
    if abs(x) < 0.5:
        t = -x                          # (-x)^n / n!, n = 1
        e = 0.0
        for n in range(2, 30):
            t *= -x / n
            e += (n - 1) * t
        return K1 * e
    return K1 * (1.0 - (1.0 + x) * math.exp(-x))


@numba.njit(cache=True)
def jh2_elastic_energy(idx, sigma, J, mode, G, K1, K2, K3, p_el, incremental, out):
    """Recoverable energy per reference volume: J S:S / (4 G) plus the volumetric
    part, eos_energy(1/J - 1) under ``pressure = "eos"``, linear_volumetric_energy(p_el)
    under ``"incremental"`` (p_el compact: entry k belongs to point idx[k]; empty
    under "eos").  The bulking pressure's work is not recoverable: it stays in the
    stress work, on the dissipated side.  0 for failed points."""
    for k in range(idx.shape[0]):
        i = idx[k]
        if mode[i] != 0:
            out[i] = 0.0
            continue
        m = (sigma[i, 0] + sigma[i, 1] + sigma[i, 2]) / 3.0
        a, b, c = sigma[i, 0] - m, sigma[i, 1] - m, sigma[i, 2] - m
        ss = a * a + b * b + c * c + 2.0 * (sigma[i, 3] ** 2 + sigma[i, 4] ** 2
                                            + sigma[i, 5] ** 2)
        if incremental:
            out[i] = J[i] * ss / (4.0 * G) + linear_volumetric_energy(p_el[k], K1)
        else:
            out[i] = J[i] * ss / (4.0 * G) + eos_energy(1.0 / J[i] - 1.0, K1, K2, K3)


@numba.njit(cache=True, inline="always")
def jh2_strength(ps, rate, D, A, N, B, M, T_star):
    """Normalised yield strength sigma_y* (Eqs. 21–23); ps = p*, rate = 1 + C ln edot*."""
    si = A * (ps + T_star) ** N * rate if ps + T_star > 0.0 else 0.0
    sf = B * ps ** M * rate if ps > 0.0 else 0.0
    return si - D * (si - sf)


def rate_factor(edot, C, rate_norm):
    """The rate term of Eqs. 21-23 for numbers or NumPy arrays (NumPy, not a kernel):
    1 + C ln edot*, edot* = edot / edot_n, clamped to 1 for edot* <= 1 (ln edot* >= 0)."""
    es = np.asarray(edot, dtype=float) / rate_norm
    return np.where(es > 1.0, 1.0 + C * np.log(np.maximum(es, 1.0)), 1.0)


def strength_envelope(ps, rate, A, N, B, M, T_star):
    """Normalised intact and fractured strengths (sigma_i*, sigma_f*) of Eqs. 21 and 23
    at p* = ``ps`` (numbers or NumPy arrays; NumPy, not a kernel), rate = 1 + C ln edot*
    (:func:`rate_factor`):
        sigma_i* = A (p* + T*)^N rate   (0 where p* + T* <= 0),
        sigma_f* = B (p*)^M rate        (0 where p* <= 0);
    the yield strength is sigma_y = sigma_HEL [sigma_i* - D (sigma_i* - sigma_f*)]
    (:func:`jh2_strength`, the kernel's)."""
    ps = np.asarray(ps, dtype=float)
    x = ps + T_star
    si = np.where(x > 0.0, A * np.maximum(x, 0.0) ** N * rate, 0.0)
    sf = np.where(ps > 0.0, B * np.maximum(ps, 0.0) ** M * rate, 0.0)
    return si, sf


class JH2Params(NamedTuple):
    """The constants of one JH2 material as :func:`jh2_kernel` reads them (SI; the
    names of Table 1 and Eqs. 19-36): shear modulus G, the EOS K1 (= lambda + 2G/3),
    K2, K3, sigma_HEL = 1.5 (HEL - p_HEL), p_HEL, the strength constants A, N, B, M,
    the rate constant C with edot_n = rate_norm, the static tensile strength T0,
    the bulking fraction beta, the damage constants D1, D2, and the pressure choice
    (``incremental``: Eq. 35, else Eq. 25).  Built by :attr:`JH2.params`; one named
    pack, so that no two constants can be swapped by position."""
    G: float
    K1: float
    K2: float
    K3: float
    sigma_hel: float
    p_hel: float
    A: float
    N: float
    B: float
    M: float
    C: float
    T0: float
    beta: float
    D1: float
    D2: float
    rate_norm: float
    incremental: bool


@numba.njit(cache=True)
def jh2_kernel(idx, d, J, dt, sigma, mode, D, eps_p, dp, p_el, pressure, rate_out,
               t_factor, prm):
    """Advance the unrotated stress of the JH2 points ``idx`` (state arrays are
    compact: entry k belongs to point idx[k]).  Sets mode[i] on failure.
    ``t_factor``: entry k's factor on T (mpipd.materials.heterogeneity), or empty;
    ``prm``: the material's :class:`JH2Params`.

    ``incremental`` False (``pressure = "eos"``): p0 = Eq. 25 at mu = 1/J - 1
    (:func:`jh2_pressure`; ``p_el`` is not read and may be empty).  True
    (``"incremental"``, Eq. 35): p0 = p_el, the hydrostatic part of Eq. 19's trial
    stress, p_el[k] -= K1 (d_xx + d_yy + d_zz) dt (d tension-positive: expansion
    lowers p); J, K2 and K3 are not read.  Either way p = p0 + dp, with p* = p /
    p_HEL in Eqs. 22, 23, 30 and the tensile check p < -T, and bulking (Eq. 26) on
    p_lin = K1 mu or p_el (the module docstring, steps 1 and 6)."""
    G, K1, K2, K3 = prm.G, prm.K1, prm.K2, prm.K3
    sigma_hel, p_hel, A, N, B, M = prm.sigma_hel, prm.p_hel, prm.A, prm.N, prm.B, prm.M
    C, T0, beta, D1, D2, rate_norm = prm.C, prm.T0, prm.beta, prm.D1, prm.D2, prm.rate_norm
    incremental = prm.incremental
    hetero = t_factor.shape[0] > 0
    for k in range(idx.shape[0]):
        i = idx[k]
        if mode[i] != 0:
            continue
        T = T0 * t_factor[k] if hetero else T0
        T_star = T / p_hel
        if incremental:
            p_el[k] -= K1 * (d[i, 0] + d[i, 1] + d[i, 2]) * dt
            p_lin = p_el[k]
            p0 = p_lin
        else:
            mu = 1.0 / J[i] - 1.0
            p_lin = K1 * mu
            p0 = jh2_pressure(mu, K1, K2, K3)
        p = p0 + dp[k]
        pressure[k] = p
        if p < -T:
            mode[i] = MODE_TENSILE
            pressure[k] = 0.0
            for c in range(6):
                sigma[i, c] = 0.0
            continue
        # deviatoric rate and trial deviator (mpipd.kernels.plasticity)
        e = deviatoric_rate(d, i)
        s = trial_deviator(sigma, i, e, G, dt)
        seq = von_mises(s)
        edot = equivalent_rate(e)
        rate_out[k] = edot
        es = edot / rate_norm
        rate = 1.0 + C * math.log(es) if es > 1.0 else 1.0
        ps = p / p_hel
        sy = sigma_hel * jh2_strength(ps, rate, D[k], A, N, B, M, T_star)
        if seq > sy:
            s = radial_return(s, seq, sy)
            deps = (seq - sy) / (3.0 * G)
            eps_p[k] += deps
            eps_f = D1 * (ps + T_star) ** D2
            D_old = D[k]
            D_new = D_old + deps / eps_f if eps_f > 0.0 else 1.0
            if D_new >= 1.0:
                D[k] = 1.0
                mode[i] = MODE_PLASTIC
                pressure[k] = 0.0
                for c in range(6):
                    sigma[i, c] = 0.0
                continue
            D[k] = D_new
            sy_new = sigma_hel * jh2_strength(ps, rate, D_new, A, N, B, M, T_star)
            dU = (sy * sy - sy_new * sy_new) / (6.0 * G)
            if dU > 0.0 and p >= 0.0:
                x = p_lin + dp[k]
                dp[k] = -p_lin + math.sqrt(x * x + 2.0 * beta * K1 * dU)
                p = p0 + dp[k]
                pressure[k] = p
        sigma[i, 0] = s[0] - p
        sigma[i, 1] = s[1] - p
        sigma[i, 2] = s[2] - p
        sigma[i, 3] = s[3]
        sigma[i, 4] = s[4]
        sigma[i, 5] = s[5]


@MATERIALS.register("jh2")
@dataclass(frozen=True)
class JH2(Material):
    """JH2 with the granite of the paper's Table 1 as defaults (SI units).

    ``bulk_modulus`` is K1.  ``pressure`` chooses the pressure of the stress
    (module docstring, step 1): ``"eos"``, Eq. 25 on the total compression, or
    ``"incremental"``, Eq. 35's hydrostatic part of Eq. 19's linear trial stress
    (K2 and K3 then unused).  ``tension`` optionally adds the rate-dependent
    tension failure model (Eqs. 37–38).
    """
    density: float = 2660.0
    bulk_modulus: float = 21.9e9          # K1
    shear_modulus: float = 25.7e9
    K2: float = -4500e9
    K3: float = 300000e9
    HEL: float = 4.5e9
    p_HEL: float = 3.7e9
    A: float = 1.9
    N: float = 0.62
    B: float = 0.25
    M: float = 0.62
    C: float = 0.005
    T: float = 54e6
    beta: float = 0.5
    D1: float = 0.005
    D2: float = 0.7
    rate_norm: float = 1.0                # edot_n of Eq. 22 (1/s)
    pressure: str = "eos"                 # one of PRESSURES
    tension: TensionFailure | None = None
    heterogeneity: object = tagged(DISTRIBUTIONS, default=None)

    def check(self, path):
        super().check(path)
        positive(self, path, "HEL", "p_HEL", "A", "N", "B", "M", "T", "D1", "D2", "rate_norm")
        non_negative(self, path, "C", "beta")
        if not self.HEL > self.p_HEL:
            fail(join(path, "HEL"), f"must exceed p_HEL ({self.HEL} <= {self.p_HEL})")
        if self.pressure not in PRESSURES:
            fail(join(path, "pressure"), f"must be one of {', '.join(map(repr, PRESSURES))} "
                 f"(got {self.pressure!r})")

    @property
    def incremental(self) -> bool:
        """True for ``pressure = "incremental"`` (Eq. 35), False for ``"eos"`` (Eq. 25)."""
        return self.pressure == "incremental"

    @cached_property
    def params(self) -> JH2Params:
        """The kernel's constants (:class:`JH2Params`), made once (the material is frozen)."""
        return JH2Params(float(self.shear_modulus), float(self.bulk_modulus), float(self.K2),
                         float(self.K3), float(self.sigma_hel), float(self.p_HEL),
                         float(self.A), float(self.N), float(self.B), float(self.M),
                         float(self.C), float(self.T), float(self.beta), float(self.D1),
                         float(self.D2), float(self.rate_norm), bool(self.incremental))

    @property
    def sigma_hel(self) -> float:
        return 1.5 * (self.HEL - self.p_HEL)

    @property
    def can_fail(self) -> bool:
        return True

    @property
    def strength_targets(self) -> tuple[str, ...]:
        return super().strength_targets + ("T",)

    def new_state(self, n: int) -> dict:
        """The history arrays; under ``pressure = "incremental"`` also ``p_el``, the
        elastic hydrostatic pressure of Eq. 19 (Pa, compression positive, 0 at the start)."""
        state = {"D": np.zeros(n), "eps_p": np.zeros(n), "dp": np.zeros(n),
                 "pressure": np.zeros(n), "strain_rate": np.zeros(n)}
        if self.incremental:
            state["p_el"] = np.zeros(n)
        return state

    def update(self, idx, d, J, dt, sigma, mode, state):
        s = state
        jh2_kernel(idx, d, J, dt, sigma, mode, s["D"], s["eps_p"], s["dp"],
                   s.get("p_el", NO_P_EL), s["pressure"], s["strain_rate"],
                   self.strength_factor(s, "T"), self.params)

    def point_strength(self, state: dict, pos: int) -> float:
        """sigma_y = sigma_HEL sigma* (p*, edot*, D) of one point (Eqs. 20–22, the
        update's own arithmetic: scalar log, the kernel's strength function)."""
        es = state["strain_rate"][pos] / self.rate_norm
        rate = 1.0 + self.C * math.log(es) if es > 1.0 else 1.0
        ps = state["pressure"][pos] / self.p_HEL
        f = self.strength_factor(state, "T")
        T = self.T * (f[pos] if len(f) else 1.0)
        return self.sigma_hel * jh2_strength(ps, rate, state["D"][pos], self.A, self.N,
                                             self.B, self.M, T / self.p_HEL)

    def elastic_energy(self, idx, sigma, J, mode, state, W, out):
        jh2_elastic_energy(idx, sigma, J, mode, self.shear_modulus, self.bulk_modulus,
                           self.K2, self.K3, state.get("p_el", NO_P_EL), self.incremental, out)

    def p_wave_speed_at(self, mu):
        """P-wave speed of the pressure law at compression mu, in the reference
        configuration the solver integrates in: the bulk stiffness is
        (1 + mu)^2 dp/dmu (= -dp/dJ, J = 1/(1 + mu)), the density rho0:
        sqrt(((1 + mu)^2 dp/dmu + 4G/3) / rho0).

        ``pressure = "eos"``: dp/dmu = K1 + 2 K2 mu + 3 K3 mu^2 (Eq. 26's tangent; K1
        where that is smaller, as in the negative-tangent range and in tension, where
        p = K1 mu).  (Measured critical steps of a confined block at mu = 0.02 and 0.1
        follow it within 5 %, once the EOS is evaluated at the end-of-step J.)
        ``"incremental"``: the bulk tangent dp/d(ln rho) is K1 at every mu (p_el =
        K1 ln(1 + mu) on an elastic path; no stiffening, no negative-tangent range),
        i.e. dp/dmu = K1 / (1 + mu) and (1 + mu)^2 dp/dmu = (1 + mu) K1."""
        mu = np.asarray(mu, dtype=float)
        k1 = self.bulk_modulus
        if self.incremental:
            k = (1.0 + mu) * k1
        else:
            tangent = np.maximum(k1 + 2.0 * self.K2 * mu + 3.0 * self.K3 * mu * mu, k1)
            k = (1.0 + mu) ** 2 * np.where(mu > 0.0, tangent, k1)
        return np.sqrt(np.maximum(k + 4.0 * self.shear_modulus / 3.0, 0.0) / self.density)

    def negative_tangent(self) -> tuple[float, float] | None:
        """The compression range (mu_lo, mu_hi) where Eq. 25's dp/dmu = K1 + 2 K2 mu +
        3 K3 mu^2 < 0; None if there is none, and under ``pressure = "incremental"``
        (the cubic is not used)."""
        if self.incremental:
            return None
        a, b, c = 3.0 * self.K3, 2.0 * self.K2, self.bulk_modulus
        if a == 0.0:
            return None if b >= 0 else (-c / b, math.inf)
        disc = b * b - 4 * a * c
        if disc <= 0:
            return None
        r = sorted(((-b - math.sqrt(disc)) / (2 * a), (-b + math.sqrt(disc)) / (2 * a)))
        if r[1] <= 0:
            return None
        return (max(r[0], 0.0), r[1])
