"""``jh2_point``: one JH2 material point on a uniaxial-strain compression path,
through yield and damage, against an ODE integration written here."""
from __future__ import annotations

import math

import numpy as np

from .common import Timer

#: Table 1 granite (the paper's JH2 constants), written out again here
JH2_TABLE1 = dict(G=25.7e9, K1=21.9e9, K2=-4500e9, K3=3e14, HEL=4.5e9, p_HEL=3.7e9, A=1.9,
                  N=0.62, B=0.25, M=0.62, C=0.005, T=54e6, beta=0.5, D1=0.005, D2=0.7)


def jh2_uniaxial_reference(rate, eps_end, t_out, prm):
    """sigma_xx, p, D of a JH2 point under uniaxial strain d = diag(rate, 0, 0) from rest,
    written from the model's equations (Johnson & Holmquist 1994; paper Eqs. 19-30):

    * elastic: deviator S_xx = (4/3) G eps (eps = rate t, the logarithmic strain),
      p = K1 mu + K2 mu^2 + K3 mu^3 with mu = exp(-eps) - 1 (mpipd's J = det F);
    * yield when (3/2)|S_xx| = sigma_y (found with brentq);
    * plastic: (3/2)|S_xx| = sigma_y(p*, D), so the plastic strain rate is
      [2 G |rate| - d sigma_y/dt] / (3 G), D' = eps_p' / eps_f(p*), and bulking
      dp' = beta K1 U' / (K1 mu + dp) with U' = -(d sigma_y^2 / dD) D' / (6 G): a
      linear system for D' solved at every RHS call, integrated with DOP853 at
      rtol 1e-11.  Well posed only while 3 G eps_f + ... > sigma_HEL (sigma_i* - sigma_f*):
      with Table 1's D1 = 0.005 it is not (the point snaps to D = 1), so the problem
      uses D1 = 0.05."""
    from scipy.integrate import solve_ivp
    from scipy.optimize import brentq
    G, K1, K2, K3 = prm["G"], prm["K1"], prm["K2"], prm["K3"]
    sh, ph = 1.5 * (prm["HEL"] - prm["p_HEL"]), prm["p_HEL"]
    Ts = prm["T"] / ph
    edot = 2.0 / 3.0 * abs(rate)
    rf = 1.0 + prm["C"] * math.log(edot) if edot > 1.0 else 1.0

    def peos(mu):
        return K1 * mu + K2 * mu * mu + K3 * mu ** 3 if mu >= 0 else K1 * mu

    def dpeos(mu):
        return K1 + 2 * K2 * mu + 3 * K3 * mu * mu if mu >= 0 else K1

    def si(ps):
        return prm["A"] * (ps + Ts) ** prm["N"] * rf

    def sf(ps):
        return prm["B"] * ps ** prm["M"] * rf if ps > 0 else 0.0

    def dsi(ps):
        return prm["A"] * prm["N"] * (ps + Ts) ** (prm["N"] - 1) * rf

    def dsf(ps):
        return prm["B"] * prm["M"] * ps ** (prm["M"] - 1) * rf if ps > 0 else 0.0

    def sy(ps, D):
        return sh * (si(ps) - D * (si(ps) - sf(ps)))

    def mu_of(t):
        return math.exp(-rate * t) - 1.0

    t_end = eps_end / rate
    ty = brentq(lambda t: 1.5 * abs(4 / 3 * G * rate * t) - sy(peos(mu_of(t)) / ph, 0.0),
                1e-15 * t_end, t_end, xtol=1e-18)

    def rhs(t, y):
        D, dp = y
        mu = mu_of(t)
        p = peos(mu) + dp
        ps = p / ph
        X = sh * (si(ps) - sf(ps))
        Y = sh * (dsi(ps) * (1 - D) + D * dsf(ps)) / ph
        Z = prm["beta"] * K1 * sy(ps, D) * X / (3 * G * (K1 * mu + dp))
        ef = prm["D1"] * (ps + Ts) ** prm["D2"]
        den = 3 * G * ef + Y * Z - X
        if not den > 0:
            raise ValueError(f"JH2 path ill-posed at t = {t:.3e} s (softening)")
        Dd = (2 * G * abs(rate) + Y * dpeos(mu) * math.exp(-rate * t) * rate) / den
        return [Dd, Z * Dd]

    sol = solve_ivp(rhs, (ty, t_end), [0.0, 0.0], rtol=1e-11, atol=1e-14,
                    dense_output=True, method="DOP853")
    out = np.empty((len(t_out), 3))
    for k, t in enumerate(t_out):
        mu = mu_of(t)
        if t <= ty:
            S, D, dp = 4 / 3 * G * rate * t, 0.0, 0.0
        else:
            D, dp = sol.sol(t)
            S = -2 / 3 * sy((peos(mu) + dp) / ph, D)
        p = peos(mu) + dp
        out[k] = (S - p, p, D)
    return out, rate * ty


class JH2Point:
    """One JH2 point (Table 1 granite, but D1 = 0.05: see the reference) driven
    through ``JH2.update`` along uniaxial-strain compression d = diag(-1000, 0, 0) 1/s
    to eps = -0.0065: elastic, yield at eps = -0.0045 inside the EOS's
    negative-dp/dmu range, then plastic flow with damage to D ~ 0.8 and bulking.  The
    resolution is the strain step |rate| dt.  Error = max over the path of
    |sigma_xx - ref| / max |ref| and |D - D_ref| (the larger).  A material point has
    no decomposition: 1 rank only."""
    name = "JH2 point, uniaxial strain"
    measure = "max(|dsigma_xx|/max|sigma|, |dD|)"
    RESOLUTIONS = (250, 500, 1000, 2000)
    QUICK = (250, 500)
    RATE, EPS_END, D1 = -1000.0, -0.0065, 0.05
    serial_only = True

    def run(self, team, n_steps, steps=None):
        from mpipd.input.schema import build
        from mpipd.materials.jh2 import JH2
        prm = dict(JH2_TABLE1, D1=self.D1)
        mat = build(JH2, {"D1": self.D1})
        dt = self.EPS_END / self.RATE / n_steps
        tm = Timer(team)
        tm.start()
        sig = np.zeros((1, 6))
        mode = np.zeros(1, np.uint8)
        st = mat.new_state(1)
        idx = np.zeros(1, np.int64)
        d = np.array([[self.RATE, 0, 0, 0, 0, 0]])
        hist = np.zeros((n_steps + 1, 3))
        for k in range(1, (steps or n_steps) + 1):
            J = np.array([math.exp(self.RATE * k * dt)])
            mat.update(idx, d, J, dt, sig, mode, st)
            hist[k] = (sig[0, 0], st["pressure"][0], st["D"][0])
        wall = tm.stop()
        if steps is not None:
            return None
        t = np.arange(n_steps + 1) * dt
        ref, eps_y = jh2_uniaxial_reference(self.RATE, self.EPS_END, t, prm)
        e_s = float(np.abs(hist[:, 0] - ref[:, 0]).max() / np.abs(ref[:, 0]).max())
        e_d = float(np.abs(hist[:, 2] - ref[:, 2]).max())
        return {"dx": abs(self.RATE) * dt, "resolution": f"d(eps) = {abs(self.RATE) * dt:.2e}",
                "points": 1, "steps": n_steps, "wall_s": wall, "error": max(e_s, e_d),
                "stress_error": e_s, "damage_error": e_d, "failed": int(mode[0]),
                "value": float(hist[-1, 2]), "reference": float(ref[-1, 2]),
                "value_name": "D at the end", "eps_yield": eps_y}
