"""Johnson–Holmquist (JH2) ceramic/rock model (Johnson & Holmquist 1994; paper §2.2, Eqs. 19–36).

Sign convention.  mpipd stresses are tension-positive; JH2's pressure p is
compression-positive, so the Cauchy stress is sigma = S - p I with S the
deviator (the paper writes Eq. 35 as sigma = S + p I in a compression-positive
frame).

Per point and step, in the unrotated frame (d from Eq. 6, dt):

1. Compression mu = rho/rho0 - 1 = 1/J - 1 (J = det F).  Pressure (Eq. 25)
       p = K1 mu + K2 mu^2 + K3 mu^3 + dp   (mu >= 0),   p = K1 mu + dp   (mu < 0).
   The pressure comes from the EOS on the total compression, as in JH2; the
   paper's Eq. 19 would integrate it incrementally, which contradicts Eq. 25.
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
       dp <- -K1 mu + sqrt((K1 mu + dp)^2 + 2 beta K1 dU)
   — only where the point is in compression (p >= 0 before the step).  Eq. 26
   is the energy balance (p_new^2 - p_old^2) / (2 K1) = beta dU of a linear
   pressure, which raises |p|; applied literally in tension (K1 mu + dp < 0)
   its positive root flips the sign of p (-44 MPa -> +44 MPa), i.e. turns a
   tensile point into a compressed one with no volume change.  Bulking is
   dilatancy of crushed material under compression (Johnson & Holmquist 1994),
   so in tension dp is left unchanged and dU is dissipated (the ledger's
   ``plastic``).  In compression p only grows, so no yield step changes its sign.
7. sigma = S - (p_EOS + dp) I (Eq. 35); the correspondence module rotates it (Eq. 36).

A failed point carries no stress; its bonds break (mpipd.model.failure).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

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
def jh2_elastic_energy(idx, sigma, J, mode, G, K1, K2, K3, out):
    """Recoverable energy per reference volume: J S:S / (4 G) + eos_energy(1/J - 1)
    (the bulking pressure's work is not recoverable: it stays in the stress work,
    on the dissipated side); 0 for failed points."""
    for k in range(idx.shape[0]):
        i = idx[k]
        if mode[i] != 0:
            out[i] = 0.0
            continue
        m = (sigma[i, 0] + sigma[i, 1] + sigma[i, 2]) / 3.0
        a, b, c = sigma[i, 0] - m, sigma[i, 1] - m, sigma[i, 2] - m
        ss = a * a + b * b + c * c + 2.0 * (sigma[i, 3] ** 2 + sigma[i, 4] ** 2
                                            + sigma[i, 5] ** 2)
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


@numba.njit(cache=True)
def jh2_update(idx, d, J, dt, sigma, mode, D, eps_p, dp, pressure, rate_out,
               G, K1, K2, K3, sigma_hel, p_hel, A, N, B, M, C, T0, beta, D1, D2, rate_norm,
               t_factor):
    """Advance the unrotated stress of the JH2 points ``idx`` (state arrays are
    compact: entry k belongs to point idx[k]).  Sets mode[i] on failure.
    ``t_factor``: entry k's factor on T (mpipd.materials.heterogeneity), or empty."""
    hetero = t_factor.shape[0] > 0
    for k in range(idx.shape[0]):
        i = idx[k]
        if mode[i] != 0:
            continue
        T = T0 * t_factor[k] if hetero else T0
        T_star = T / p_hel
        mu = 1.0 / J[i] - 1.0
        p_eos = jh2_pressure(mu, K1, K2, K3)
        p = p_eos + dp[k]
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
                x = K1 * mu + dp[k]
                dp[k] = -K1 * mu + math.sqrt(x * x + 2.0 * beta * K1 * dU)
                p = p_eos + dp[k]
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

    ``bulk_modulus`` is K1.  ``tension`` optionally adds the rate-dependent
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
    tension: TensionFailure | None = None
    heterogeneity: object = tagged(DISTRIBUTIONS, default=None)

    def check(self, path):
        super().check(path)
        positive(self, path, "HEL", "p_HEL", "A", "N", "B", "M", "T", "D1", "D2", "rate_norm")
        non_negative(self, path, "C", "beta")
        if not self.HEL > self.p_HEL:
            fail(join(path, "HEL"), f"must exceed p_HEL ({self.HEL} <= {self.p_HEL})")

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
        return {"D": np.zeros(n), "eps_p": np.zeros(n), "dp": np.zeros(n),
                "pressure": np.zeros(n), "strain_rate": np.zeros(n)}

    def update(self, idx, d, J, dt, sigma, mode, state):
        s = state
        jh2_update(idx, d, J, dt, sigma, mode, s["D"], s["eps_p"], s["dp"], s["pressure"],
                   s["strain_rate"], self.shear_modulus, self.bulk_modulus, self.K2, self.K3,
                   self.sigma_hel, self.p_HEL, self.A, self.N, self.B, self.M, self.C, self.T,
                   self.beta, self.D1, self.D2, self.rate_norm, self.strength_factor(s, "T"))

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
                           self.K2, self.K3, out)

    def p_wave_speed_at(self, mu):
        """P-wave speed of the EOS at compression mu, in the reference configuration the
        solver integrates in: the bulk stiffness is J dp/dJ = (1 + mu)^2 dp/dmu with
        dp/dmu = K1 + 2 K2 mu + 3 K3 mu^2 (Eq. 26's tangent; K1 where that is smaller,
        as in the negative-tangent range and in tension, where p = K1 mu), the density
        rho0: sqrt(((1 + mu)^2 dp/dmu + 4G/3) / rho0).  (Measured critical steps of a
        confined block at mu = 0.02 and 0.1 follow it within 5 %, once the EOS is
        evaluated at the end-of-step J.)"""
        mu = np.asarray(mu, dtype=float)
        k1 = self.bulk_modulus
        tangent = np.maximum(k1 + 2.0 * self.K2 * mu + 3.0 * self.K3 * mu * mu, k1)
        k = (1.0 + mu) ** 2 * np.where(mu > 0.0, tangent, k1)
        return np.sqrt(np.maximum(k + 4.0 * self.shear_modulus / 3.0, 0.0) / self.density)

    def negative_tangent(self) -> tuple[float, float] | None:
        """The compression range (mu_lo, mu_hi) where dp/dmu = K1 + 2 K2 mu + 3 K3 mu^2 < 0."""
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
