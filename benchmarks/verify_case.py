"""Verification problems for `make verify` (benchmarks/verify.py runs this under mpirun).

    mpirun -n R python benchmarks/verify_case.py PROBLEM[,PROBLEM...] [--res 0,1] [--quick]

prints, on rank 0, one line per resolution:  ``VERIFY {json}``  with the problem,
the resolution, the point count, the ranks, the wall time of the case (model
set-up plus time loop, the slowest rank's; the interpreter start and a small
untimed warm-up that loads the numba kernels are excluded) and the error
measure against an answer computed here, independently of the solver.

Every reference below comes from closed-form continuum mechanics or from an
integration written in this file; none calls the solver's own formulas.

Problems (each a class with ``RESOLUTIONS``, ``QUICK`` and ``run(team, res)``):

``wave``        plane P wave in granite: the speed of the pulse's kinetic-energy
                centroid against sqrt((K + 4G/3)/rho).  1-D strain is imposed by the
                harness (the
                lateral acceleration and velocity of every point are zeroed after
                each step: rollers on the lateral faces, i.e. a laterally infinite
                plate), so the reference is exactly c_p, not the bar speed.
``lame``        thick elastic cylinder under internal pressure (Lame), free slab
                (see :class:`Lame` for why a free slab is exact), dynamic
                relaxation with mass-proportional damping set by the harness;
                sigma_rr and sigma_tt more than a horizon from every surface.
``energy``      free elastic block with a smooth velocity field: drift of the total
                energy per 1000 steps, and its largest deviation.
``jh2_point``   one JH2 material point on a uniaxial-strain compression path,
                through yield and damage, against an ODE integration written here.
``detonation``  explosive column in a copper tube: the detonation front position
                against z0 + VOD t, and the JWL pressure of every burnt gas point
                against the closed-form isentrope through its state when fully lit.
``isentrope_dt`` the same at one dx with dt refined alone.

Two hooks reach past the scene file, both in this harness only: the wave's lateral
rollers (the solver has no per-component boundary condition) and the Lame
cylinder's global damping (the solver's damping acts on failed points only).
"""
from __future__ import annotations

import argparse
import json
import math
import sys
import time

import numpy as np

RHO, K_GR, G_GR = 2660.0, 21.9e9, 25.7e9          # the paper's granite (§3.1)
C_P = math.sqrt((K_GR + 4.0 * G_GR / 3.0) / RHO)


def granite():
    return {"model": "elastic", "density": RHO, "bulk_modulus": K_GR, "shear_modulus": G_GR}


def build_scene(d):
    from mpipd.input.schema import build
    from mpipd.input.scene import Scene
    return build(Scene, d)


def stable_step(scene) -> float:
    """The step `mpipd run` accepts at most (the Silling-Askari / CFL estimate)."""
    from mpipd.check import critical_dt
    return critical_dt(scene)


class Timer:
    """Wall time of the slowest rank between start() and stop()."""

    def __init__(self, team):
        self.team = team

    def start(self):
        self.team.barrier()
        self.t0 = time.perf_counter()

    def stop(self) -> float:
        return self.team.max(time.perf_counter() - self.t0)


def timed_simulation(team, scene):
    """Start the clock (set-up counts as run time) and build the Simulation."""
    from mpipd.solver import Simulation
    tm = Timer(team)
    tm.start()
    return tm, Simulation(scene, team)


# ----------------------------------------------------------------------------- wave

class Wave:
    """Plane P wave: a cos^2 velocity pulse (half-width 20 mm at every dx) launched
    from the free end x = 0 of a 192 mm bar whose cross-section is 6 x 6 lattice
    points; 1-D strain by the harness.  The speed is the least-squares slope of the
    kinetic-energy centroid of the pulse (planes with x > 25 mm) over 12..30 us, once
    the pulse has left the end: the energy transport speed, which is c_p exactly for
    a non-dispersive continuum.  (Peak arrival times are noisier: the pulse's peak
    wobbles by a fraction of dx as dispersion reshapes it.)  dt = 0.45 of the
    stable estimate at every dx."""
    name = "P-wave speed"
    measure = "|c - c_p| / c_p"
    RESOLUTIONS = (2.0e-3, 1.4e-3, 1.0e-3, 0.7e-3)
    QUICK = (2.0e-3, 1.4e-3)
    LENGTH, HALF_WIDTH = 0.192, 0.02
    X_MIN, T_FIT, T_END = 0.025, (12e-6, 30e-6), 30e-6

    def scene(self, dx, steps=None):
        n_lat = 6
        d = {"scene": {"name": "verify_wave"},
             "time": {"dt": 1e-9, "steps": 1},
             "materials": {"granite": granite()},
             "parts": [{"name": "bar", "material": "granite", "dx": dx,
                        "shape": {"kind": "box", "lo": [0, 0, 0],
                                  "hi": [self.LENGTH, n_lat * dx, n_lat * dx]}}],
             "initial": [{"kind": "velocity_pulse", "axis": "x", "center": 0.0,
                          "half_width": self.HALF_WIDTH, "velocity": [1.0, 0.0, 0.0]}]}
        dt = 0.45 * stable_step(build_scene(d))
        d["time"] = {"dt": dt, "steps": steps if steps is not None
                     else int(math.ceil(self.T_END / dt))}
        return build_scene(d)

    @staticmethod
    def constrain(sim):
        """Rollers on the lateral faces: no lateral acceleration or velocity anywhere."""
        sim.a[:, 1:] = 0.0
        sim.v[: sim.points.n_owned, 1:] = 0.0

    def run(self, team, dx, steps=None):
        scene = self.scene(dx, steps)
        tm, sim = timed_simulation(team, scene)
        n = sim.points.n_owned
        x = sim.points.x[:n, 0]
        n_planes = int(round(self.LENGTH / dx))
        plane = np.minimum((x / dx).astype(np.int64), n_planes - 1)   # lattice plane index
        xs = (np.arange(n_planes) + 0.5) * dx
        cnt = team.sum(np.bincount(plane, minlength=n_planes).astype(float))
        self.constrain(sim)
        t, vx = [], []
        for _ in range(scene.time.n_steps):
            sim.step()
            self.constrain(sim)
            if self.T_FIT[0] <= sim.t <= self.T_FIT[1] + 0.5 * sim.dt:
                t.append(sim.t)
                vx.append(np.bincount(plane, weights=sim.v[:n, 0], minlength=n_planes))
        sim.check_finite()
        wall = tm.stop()
        if steps is not None:
            return None
        vx = team.sum(np.array(vx)) / cnt                 # section-mean v_x, (frames, planes)
        e = vx ** 2 * (xs > self.X_MIN)
        centroid = (e @ xs) / e.sum(axis=1)
        c = float(np.polyfit(np.array(t), centroid, 1)[0])
        return {"dx": dx, "points": sim.n_global, "steps": scene.time.n_steps, "wall_s": wall,
                "error": abs(c - C_P) / C_P, "value": c, "reference": C_P,
                "value_name": "c (m/s)"}


# ----------------------------------------------------------------------------- Lame

class Lame:
    """Thick-walled elastic cylinder under internal pressure (Lame): granite annulus,
    a = 6 mm, b = 18 mm, 8 lattice levels thick with free faces; p = 10 MPa on the
    inner wall (the `borehole_pressure` load, ramped over 5 us, then held); mass-
    proportional damping c = 7e5 1/s on every point (about twice the breathing
    mode's frequency: critical for it) set by the harness in the solver's damping
    array (scene options damp only failed points).  The kinetic energy decays as
    exp(-c t) for the modes near the breathing mode, slower for the rest: after
    28 us it is about 1e-6 of its peak (``ke_end_over_peak``); the error then
    changes by under 1 % of itself between 18 and 28 us.

    Why a free slab.  For internal pressure alone, sigma_rr = A - B/r^2,
    sigma_tt = A + B/r^2 with A = p a^2/(b^2 - a^2), B = A b^2 hold for plane strain
    and, with sigma_zz = 0 and a uniform eps_zz (sigma_rr + sigma_tt = 2A is
    constant), as an exact 3-D solution of a slab of any thickness with free faces.
    In the correspondence model a free z face under a uniform in-plane stress with
    sigma_zz = 0 carries no spurious force (the family is symmetric in x and y), so
    the slab needs neither a z constraint nor periodicity.

    Compared: sigma_rr and sigma_tt of every point with r - a > 3.5 mm and
    b - r > 3.5 mm (more than a horizon from the walls at every dx here: delta is
    3 mm at dx = 1 mm) on the levels more than a horizon from both faces.  Error =
    RMS over those points of both components, divided by p.  Points within about
    three horizons of the curved staircase walls carry larger, non-converging
    errors (reported as ``near_wall_max``)."""
    name = "Lame cylinder"
    measure = "rms(sigma - Lame) / p"
    RESOLUTIONS = (1.0e-3, 0.7e-3, 0.5e-3, 0.35e-3)
    QUICK = (1.0e-3, 0.85e-3)
    A_IN, B_OUT, P, NZ = 0.006, 0.018, 10e6, 8
    BAND, DAMPING, RAMP, T_END = 0.0035, 7e5, 5e-6, 28e-6

    def scene(self, dx, steps=None):
        d = {"scene": {"name": "verify_lame"},
             "time": {"dt": 1e-9, "steps": 1},
             "materials": {"granite": granite()},
             "parts": [{"name": "ring", "material": "granite", "dx": dx,
                        "shape": {"kind": "annulus", "center": [0, 0],
                                  "inner_radius": self.A_IN, "radius": self.B_OUT,
                                  "z": [0, self.NZ * dx]}}],
             "loads": [{"kind": "borehole_pressure", "center": [0, 0], "radius": self.A_IN,
                        "times": [0.0, self.RAMP, 1.0], "pressures": [0.0, self.P, self.P]}]}
        dt = 0.45 * stable_step(build_scene(d))
        d["time"] = {"dt": dt, "steps": steps if steps is not None
                     else int(math.ceil(self.T_END / dt))}
        return build_scene(d)

    def reference(self, r):
        a, b, p = self.A_IN, self.B_OUT, self.P
        A = p * a * a / (b * b - a * a)
        B = A * b * b
        return A - B / r ** 2, A + B / r ** 2

    def run(self, team, dx, steps=None):
        scene = self.scene(dx, steps)
        tm, sim = timed_simulation(team, scene)
        n = sim.points.n_owned
        sim.damp = np.full(n, self.DAMPING)          # harness: global mass-proportional damping
        ke_peak = 0.0
        for _ in range(scene.time.n_steps):
            sim.step()
            if sim.step_count % 20 == 0:
                ke_peak = max(ke_peak, sim.energies().kinetic)
        ke_end = sim.energies().kinetic
        sim.check_finite()
        wall = tm.stop()
        if steps is not None:
            return None
        x = sim.points.x[:n]
        r = np.hypot(x[:, 0], x[:, 1])
        delta = scene.parts[0].horizon
        level = np.round(x[:, 2] / dx - 0.5).astype(np.int64)
        zin = (level * dx + 0.5 * dx > delta) & ((self.NZ - level - 0.5) * dx > delta)
        s = sim.corr.cauchy_stress()
        er = x[:, :2] / r[:, None]
        srr = s[:, 0] * er[:, 0] ** 2 + s[:, 1] * er[:, 1] ** 2 + 2 * s[:, 5] * er[:, 0] * er[:, 1]
        stt = s[:, 0] * er[:, 1] ** 2 + s[:, 1] * er[:, 0] ** 2 - 2 * s[:, 5] * er[:, 0] * er[:, 1]
        rr, tt = self.reference(r)
        err = np.concatenate([srr - rr, stt - tt]) / self.P
        band = np.tile(zin & (r - self.A_IN > self.BAND) & (self.B_OUT - r > self.BAND), 2)
        near = np.tile(zin & (r - self.A_IN > delta) & (self.B_OUT - r > delta), 2) & ~band
        sq = team.sum(np.array([np.sum(err[band] ** 2), band.sum(),
                                np.sum(s[zin[:n] & (r - self.A_IN > self.BAND), 2] ** 2)]))
        near_max = team.max(float(np.abs(err[near]).max()) if near.any() else 0.0)
        band_max = team.max(float(np.abs(err[band]).max()) if band.any() else 0.0)
        return {"dx": dx, "points": sim.n_global, "steps": scene.time.n_steps, "wall_s": wall,
                "error": float(math.sqrt(sq[0] / sq[1])), "band_max": band_max,
                "near_wall_max": near_max, "compared": int(sq[1] // 2),
                "ke_end_over_peak": ke_end / ke_peak,
                "value": band_max, "reference": 0.0, "value_name": "max |error| / p"}


# ----------------------------------------------------------------------------- energy

class Energy:
    """Free elastic granite cube, 16 mm, with a smooth velocity field
    v = (1, 0.5, 0.25) m/s * cos^2(pi (x - 8 mm) / 16 mm) (compression and shear,
    vanishing with its slope at both ends); no load, no boundary condition, dt = 0.45
    of the stable estimate, 200 us (about 60 P-wave transits).  Two rows: the drift
    per 1000 steps (least-squares slope of the total energy over the steps, after
    the first 10 %, times 1000 / E0) and the largest |E - E0| / E0."""
    name = "energy, free body"
    RESOLUTIONS = (2.0e-3, 1.6e-3, 1.333e-3, 1.0e-3)
    QUICK = (2.0e-3, 1.6e-3)
    L, T_END = 0.016, 200e-6

    def scene(self, dx, steps=None):
        L = self.L
        d = {"scene": {"name": "verify_energy"},
             "time": {"dt": 1e-9, "steps": 1},
             "materials": {"granite": granite()},
             "parts": [{"name": "cube", "material": "granite", "dx": dx,
                        "shape": {"kind": "box", "lo": [0, 0, 0], "hi": [L, L, L]}}],
             "initial": [{"kind": "velocity_pulse", "axis": "x", "center": L / 2,
                          "half_width": L / 2, "velocity": [1.0, 0.5, 0.25]}]}
        dt = 0.45 * stable_step(build_scene(d))
        d["time"] = {"dt": dt, "steps": steps if steps is not None
                     else int(math.ceil(self.T_END / dt))}
        return build_scene(d)

    def run(self, team, dx, steps=None):
        scene = self.scene(dx, steps)
        tm, sim = timed_simulation(team, scene)
        E, S = [sim.energies().total], [0]
        for _ in range(scene.time.n_steps):
            sim.step()
            if sim.step_count % 5 == 0:
                E.append(sim.energies().total)
                S.append(sim.step_count)
        wall = tm.stop()
        if steps is not None:
            return None
        E, S = np.array(E), np.array(S)
        keep = S >= 0.1 * S[-1]
        (slope, _), cov = np.polyfit(S[keep], E[keep], 1, cov=True)
        drift = slope * 1000.0 / E[0]
        drift_se = math.sqrt(cov[0, 0]) * 1000.0 / E[0]
        dev = float(np.abs(E - E[0]).max() / E[0])
        base = {"dx": dx, "points": sim.n_global, "steps": scene.time.n_steps, "wall_s": wall}
        return [dict(base, problem="energy drift / 1000 steps", measure="|dE/E0| per 1000 steps",
                     error=abs(drift), value=drift, value_se=drift_se, reference=0.0,
                     value_name="drift per 1000 steps"),
                dict(base, problem="energy, max deviation", measure="max |E - E0| / E0",
                     error=dev, value=dev, reference=0.0, value_name="max |dE|/E0")]


# ----------------------------------------------------------------------------- JH2 point

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
        from mpipd.materials.jh2 import JH2
        from mpipd.input.schema import build
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


# ----------------------------------------------------------------------------- detonation

#: Table 2 (the paper's JWL explosive), written out again here
JWL_TABLE2 = dict(rho=1320.0, A=568e9, B=21.6e9, R1=5.81, R2=1.77, w=0.282, e0=7.38e9,
                  vod=6690.0)


def jwl_p(V, e, c=JWL_TABLE2):
    return (c["A"] * (1 - c["w"] / (c["R1"] * V)) * np.exp(-c["R1"] * V)
            + c["B"] * (1 - c["w"] / (c["R2"] * V)) * np.exp(-c["R2"] * V) + c["w"] * e / V)


def jwl_isentrope(V, V1, p1, c=JWL_TABLE2):
    """Pressure on the isentrope through (V1, p1): A e^-R1V + B e^-R2V + C V^-(1+w)."""
    C = (p1 - c["A"] * np.exp(-c["R1"] * V1) - c["B"] * np.exp(-c["R2"] * V1)) * V1 ** (1 + c["w"])
    return c["A"] * np.exp(-c["R1"] * V) + c["B"] * np.exp(-c["R2"] * V) + C * V ** -(1 + c["w"])


class Detonation:
    """Explosive column (Table 2, radius 3.2 mm, 16 mm long) in a copper tube (J2,
    3.2-5.2 mm), one dx for both, detonated from z = 0; no gas damping; 2.0 us at
    dt = 0.3 of the stable estimate.  Two rows from the same runs:

    * front: the z where the mean pressure of the gas within 1.6 mm of the axis
      first reaches p(V = 1, e0)/2 coming from ahead (linear between levels), at
      every step from 0.6 us; error = |z_f - VOD t| / (VOD t) at the end.  The
      programmed burn ramps over 3 dx / VOD, so the front lags by about 1.5 dx by
      construction: first order.  ``value`` is the fitted front speed.
    * isentrope: every gas point, from the first step it is fully lit, follows
      de = -p dV (no shock inside the gas: the burn is programmed), so its pressure
      must stay on the closed-form JWL isentrope through its state at that step;
      error = max over burnt points of |p - p_s(V)| at the end, over p(1, e0) =
      6.79 GPa.  The gas energy update is explicit in the volume step, and through
      the burn front (3 dx wide) the volume change per step does not shrink with dx
      at a fixed dt / dt_stable, so this error does not converge under refinement
      of dx; :class:`IsentropeDt` refines dt alone and shows first order."""
    isentrope_name = "JWL isentrope (dx refined)"
    DT_FRACTION = 0.3
    name = "detonation front"
    measure = "|z_f - VOD t| / (VOD t)"
    RESOLUTIONS = (0.8e-3, 0.57e-3, 0.4e-3)
    QUICK = (1.0e-3, 0.8e-3)
    R_GAS, R_TUBE, LENGTH, T_END, T_FIT = 0.0032, 0.0052, 0.016, 2.0e-6, 0.6e-6

    def scene(self, dx, steps=None, frac=None):
        z = [0.0, self.LENGTH]
        d = {"scene": {"name": "verify_detonation"},
             "time": {"dt": 1e-9, "steps": 1},
             "materials": {"explosive": {"model": "jwl", "damping": 0.0,
                                         "interacts_with": ["copper"]},
                           "copper": {"model": "j2"}},
             "parts": [{"name": "charge", "material": "explosive", "dx": dx,
                        "shape": {"kind": "cylinder", "center": [0, 0], "radius": self.R_GAS,
                                  "z": z}},
                       {"name": "tube", "material": "copper", "dx": dx,
                        "shape": {"kind": "annulus", "center": [0, 0],
                                  "inner_radius": self.R_GAS, "radius": self.R_TUBE, "z": z}}]}
        dt = (frac or self.DT_FRACTION) * stable_step(build_scene(d))
        d["time"] = {"dt": dt, "steps": steps if steps is not None
                     else int(math.ceil(self.T_END / dt))}
        return build_scene(d)

    def dt_fraction(self, res):
        return self.DT_FRACTION

    def dx_of(self, res):
        return res

    def run(self, team, res, steps=None):
        dx = self.dx_of(res)
        scene = self.scene(dx, steps, self.dt_fraction(res))
        c = JWL_TABLE2
        p_half = 0.5 * float(jwl_p(1.0, c["e0"]))
        tm, sim = timed_simulation(team, scene)
        gas = sim.gas
        gi = gas.gas_idx
        x = sim.points.x[gi]
        axis = np.hypot(x[:, 0], x[:, 1]) < 0.5 * self.R_GAS
        n_lev = int(round(self.LENGTH / dx))
        lev = np.minimum((x[:, 2] / dx).astype(np.int64), n_lev - 1)
        zs = (np.arange(n_lev) + 0.5) * dx
        cnt = team.sum(np.bincount(lev[axis], minlength=n_lev).astype(float))
        V1 = np.full(len(gi), np.nan)                 # state when first fully lit
        p1 = np.full(len(gi), np.nan)
        ts, fronts = [], []
        for _ in range(scene.time.n_steps):
            sim.step()
            V = gas.gd[gi, 6] / gas.V0
            p = gas.gd[gi, 7]
            lit = np.isnan(V1) & (sim.t >= gas.t_lit + gas.t_ramp + 1e-15)
            V1[lit], p1[lit] = V[lit], p[lit]
            if sim.t >= self.T_FIT:
                prof = team.sum(np.bincount(lev[axis], weights=p[axis], minlength=n_lev)) / cnt
                fronts.append(front(zs, prof, p_half))
                ts.append(sim.t)
        sim.check_finite()
        wall = tm.stop()
        if steps is not None:
            return None
        V = gas.gd[gi, 6] / gas.V0
        p = gas.gd[gi, 7]
        burnt = ~np.isnan(V1)
        ps = jwl_isentrope(V[burnt], V1[burnt], p1[burnt])
        p_cv = 2.0 * p_half
        e_is = team.max(float(np.abs(p[burnt] - ps).max() / p_cv) if burnt.any() else 0.0)
        rel = team.max(float(np.max(np.abs(p[burnt] - ps) / ps)) if burnt.any() else 0.0)
        v_max = team.max(float(V.max()) if len(V) else 0.0)
        n_burnt = team.sum(int(burnt.sum()))
        ts, fronts = np.array(ts), np.array(fronts)
        D = c["vod"]
        speed = float(np.polyfit(ts, fronts, 1)[0])
        err_f = abs(fronts[-1] - D * ts[-1]) / (D * ts[-1])
        base = {"dx": dx, "points": sim.n_global, "steps": scene.time.n_steps, "wall_s": wall,
                "dt": scene.time.dt}
        return [dict(base, error=err_f, value=speed, reference=D, value_name="front speed (m/s)",
                     lag_dx=(D * ts[-1] - fronts[-1]) / dx),
                dict(base, problem=self.isentrope_name, measure="max |p - p_s(V)| / p(1, e0)",
                     error=e_is, value=v_max, reference=None, value_name="largest V/V0",
                     max_rel=rel, burnt_points=n_burnt)]


class IsentropeDt(Detonation):
    """The detonation problem at dx = 0.8 mm with dt = 0.3, 0.15, 0.075 of the stable
    estimate: the isentrope error against dt alone (the front row is dropped)."""
    name = "JWL isentrope (dt refined, dx 0.8 mm)"
    isentrope_name = name
    RESOLUTIONS = (0.3, 0.15, 0.075)
    QUICK = (0.3, 0.15)

    def dt_fraction(self, res):
        return res

    def dx_of(self, res):
        return 0.8e-3

    def run(self, team, res, steps=None):
        rows = super().run(team, res, steps)
        if rows is None:
            return None
        row = rows[1]
        row["resolution"] = f"dt = {res:g} dt_stable"
        row["dx"] = row["dt"]
        return [row]


def front(zs, prof, level):
    """Largest z where the profile reaches ``level`` coming from high z (linear)."""
    above = np.flatnonzero(prof >= level)
    if not len(above):
        return float("nan")
    k = above[-1]
    if k + 1 >= len(zs):
        return float(zs[k])
    f0, f1 = prof[k], prof[k + 1]
    return float(zs[k] + (f0 - level) / (f0 - f1) * (zs[k + 1] - zs[k]))


# ----------------------------------------------------------------------------- main

PROBLEMS = {"wave": Wave, "lame": Lame, "energy": Energy, "jh2_point": JH2Point,
            "detonation": Detonation, "isentrope_dt": IsentropeDt}


def main(argv=None):
    ap = argparse.ArgumentParser()
    ap.add_argument("problems", help="comma-separated: " + ", ".join(sorted(PROBLEMS)))
    ap.add_argument("--res", default=None, help="comma-separated resolution indices")
    ap.add_argument("--quick", action="store_true")
    args = ap.parse_args(argv)
    keys = args.problems.split(",")
    for key in keys:
        if key not in PROBLEMS:
            ap.error(f"unknown problem {key!r}")
    from mpi4py import MPI

    from mpipd.parallel.team import Team
    team = Team(MPI.COMM_WORLD)
    for key in keys:
        prob = PROBLEMS[key]()
        if team.size > 1 and getattr(prob, "serial_only", False):
            continue
        table = prob.QUICK if args.quick else prob.RESOLUTIONS
        idx = range(len(table)) if args.res is None else map(int, args.res.split(","))
        prob.run(team, table[0], steps=2)          # untimed: loads the numba kernels
        for k in idx:
            out = prob.run(team, table[k])
            rows = out if isinstance(out, list) else [out]
            if team.root:
                for r in rows:
                    r.setdefault("problem", prob.name)
                    r.setdefault("measure", getattr(prob, "measure", ""))
                    r["key"] = key
                    r["ranks"] = team.size
                    print("VERIFY " + json.dumps(r), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
