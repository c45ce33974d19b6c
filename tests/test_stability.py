"""Stiff and extreme cases: each is either stable — no NaN, the energy bounded by the
input work, damage monotone — or refused (or, where it cannot be known before the
run, detected) with a clear message.

"Energy bounded" is checked on the solver's own record: total(t) - total(0) <=
external work + tol * scale, where tol covers the O((omega dt)^2) error with which
velocity Verlet measures the energy (about 1e-3 at dt = 0.5 dt_c, 2e-2 at 0.9 dt_c
in these small blocks; tests/test_verify.py measures it against resolution).
"""
import math
import re

import numpy as np
import pytest
from conftest import free_charge, make_scene, run_cli

from mpipd.check import check_report
from mpipd.materials.jh2 import JH2
from mpipd.materials.jwl import JWL
from mpipd.materials.tension import dynamic_strength
from mpipd.model.stability import critical_dt
from mpipd.solver import Simulation, Unstable


def box_scene(material, dx, n, dt_factor=0.5, steps=200, solver=None, initial=(),
              name="stab"):
    """An n x n x n block of one material; dt = dt_factor x the critical step."""
    L = n * dx
    d = {"scene": {"name": name},
         "time": {"dt": 1e-9, "steps": steps},
         "materials": {"m": material},
         "parts": [{"name": "b", "material": "m", "dx": dx,
                    "shape": {"kind": "box", "lo": [0, 0, 0], "hi": [L, L, L]}}],
         "solver": solver or {"hourglass": 0.01},
         "initial": list(initial)}
    d["time"]["dt"] = dt_factor * critical_dt(make_scene(d))
    return d


class Watch:
    """Steps a simulation and checks, every ``every`` steps: finite fields, total
    energy within input work, PD damage phi, failure flags and JH2 damage
    non-decreasing per point."""

    def __init__(self, sim, tol=1e-3, scale=None):
        self.sim = sim
        e = sim.energies()
        self.e0 = e.total
        self.scale = scale if scale is not None else max(abs(e.total), 1e-30)
        self.tol = tol
        self.worst = -math.inf          # max of (total - total0 - external) / scale
        self.snap = self._state()

    def _state(self):
        s = self.sim
        phi = s.failure.phi.copy() if s.failure is not None else None
        mode = s.mode[: s.points.n_owned].copy()
        D = [g.state["D"].copy() for g in s.corr.groups if "D" in g.state]
        return phi, mode, D

    def run(self, steps, every=5):
        s = self.sim
        for _ in range(steps):
            s.step()
            if s.step_count % every == 0:
                self.check()
        self.check()
        return self

    def check(self):
        s = self.sim
        s.check_finite()
        e = s.energies()
        self.worst = max(self.worst, (e.total - self.e0 - e.external) / self.scale)
        assert self.worst <= self.tol, f"energy grew by {self.worst:.3e} of the input"
        phi, mode, D = self._state()
        phi0, mode0, D0 = self.snap
        if phi is not None:
            assert np.all(phi >= phi0 - 1e-15), "PD damage decreased"
            assert np.all(phi <= 1.0 + 1e-15) and np.all(phi >= 0.0)
        assert np.all(mode[mode0 != 0] == mode0[mode0 != 0]), "a failed point healed"
        for a, b in zip(D, D0):
            assert np.all(a >= b) and np.all(a <= 1.0), "JH2 damage decreased or exceeded 1"
        self.snap = (phi, mode, D)


# ----------------------------------------------------------------------------- copper dt

COPPER = {"model": "j2"}                 # rho 8960, K 130 GPa, G 45 GPa, sigma_y 450 MPa
PULSE = [{"kind": "velocity_pulse", "axis": "x", "center": 0.0018, "half_width": 0.0018,
          "velocity": [2.0, 1.0, 0.0]}]


def copper(dt_factor, steps=400):
    return box_scene(COPPER, 3e-4, 12, dt_factor, steps, initial=PULSE, name="copper")


@pytest.mark.parametrize("factor,tol", [(0.5, 5e-3), (0.9, 2e-2)])
def test_copper_stable_below_the_critical_step(team, factor, tol):
    sim = Simulation(make_scene(copper(factor)), team)
    w = Watch(sim, tol=tol).run(400)
    assert sim.energies().kinetic > 0.1 * w.e0        # still moving: nothing was lost


def write_toml(path, d):
    def val(v):
        if isinstance(v, dict):
            return "{ " + ", ".join(f"{k} = {val(x)}" for k, x in v.items()) + " }"
        if isinstance(v, (list, tuple)):
            return "[" + ", ".join(val(x) for x in v) + "]"
        if isinstance(v, str):
            return f'"{v}"'
        if isinstance(v, bool):
            return "true" if v else "false"
        return repr(v)
    lines = []
    for table in ("scene", "time", "solver"):
        lines.append(f"[{table}]")
        lines += [f"{k} = {val(v)}" for k, v in d[table].items()]
    for m, body in d["materials"].items():
        lines.append(f"[materials.{m}]")
        lines += [f"{k} = {val(v)}" for k, v in body.items()]
    for arr in ("parts", "initial"):
        for item in d[arr]:
            lines.append(f"[[{arr}]]")
            lines += [f"{k} = {val(v)}" for k, v in item.items()]
    lines += ["[output]", "every = 50", 'fields = ["u", "v"]']
    path.write_text("\n".join(lines) + "\n")
    return path


def test_copper_above_the_critical_step_is_refused_unless_forced(tmp_path):
    f = write_toml(tmp_path / "cu.toml", copper(1.1, steps=300))
    res = run_cli(["run", str(f), "--out", str(tmp_path / "a"), "--quiet"])
    assert res.returncode == 2, res.stdout + res.stderr
    assert "exceeds the stable estimate" in res.stderr and "--force" in res.stderr
    assert not (tmp_path / "a" / "run.h5").exists()
    chk = run_cli(["check", str(f)])
    assert chk.returncode == 2 and "TOO LARGE" in chk.stdout and "'m' (j2)" in chk.stdout
    # forced: the run goes ahead with a warning.  The Silling-Askari estimate is
    # conservative for the correspondence model (measured: copper at 0.3 mm runs
    # stably to 1.7 x and blows up at 1.85 x), so at 1.1 x it completes
    res = run_cli(["run", str(f), "--out", str(tmp_path / "b"), "--quiet", "--force"])
    assert res.returncode == 0, res.stdout + res.stderr
    assert "warning" in res.stdout and "exceeds the stable estimate" in res.stdout


def test_copper_blow_up_is_detected_and_reported(tmp_path):
    f = write_toml(tmp_path / "cu.toml", copper(2.5, steps=300))
    res = run_cli(["run", str(f), "--out", str(tmp_path / "c"), "--quiet", "--force"])
    assert res.returncode == 3, res.stdout + res.stderr
    assert ("non-finite" in res.stderr or "|v_j - v_i| dt > |xi|" in res.stderr)
    assert "compare dt with `mpipd check`" in res.stderr
    assert (tmp_path / "c" / "checkpoint_failed.h5").exists()        # the state, for a look


def test_copper_blow_up_detected_in_process(team):
    sim = Simulation(make_scene(copper(2.5)), team)
    with pytest.raises(Unstable, match=r"non-finite|\|v_j - v_i\| dt > \|xi\|"):
        sim.run(400)
    assert sim.step_count < 400


# ----------------------------------------------------------------------------- JH2 EOS

JH2_PLAIN = {"model": "jh2"}             # Table 1, no tension model


def compress(sim, mu):
    """Impose a uniform hydrostatic compression mu (J = 1 / (1 + mu)) and its forces."""
    n = sim.points.n_owned
    s = (1.0 / (1.0 + mu)) ** (1.0 / 3.0) - 1.0
    c = sim.points.x[: sim.points.n_local].mean(axis=0)
    sim.u[:] = s * (sim.points.x - c)
    sim.initialize()
    return n


def stored_energy(mu, mat=JH2()):
    """Elastic energy per reference volume of a hydrostatic compression mu (Eq. 25):
    the integral of p dV from J = 1 down to 1/(1 + mu), written out here."""
    from scipy.integrate import quad

    def p(m):
        return mat.bulk_modulus * m + mat.K2 * m * m + mat.K3 * m ** 3
    return quad(lambda m: p(m) / (1.0 + m) ** 2, 0.0, mu)[0]


def release(team, mu, factor=0.5):
    """A JH2 block released from a uniform compression mu: stable, the kinetic energy
    never above the stored energy (computed here from Eq. 25), failures (tension at
    the surfaces) only accumulate."""
    d = box_scene(JH2_PLAIN, 1e-3, 8, factor, 150)
    scene = make_scene(d)
    line = [ln for ln in check_report(scene, 1).splitlines() if "EOS stiffening" in ln][0]
    assert mu < float(line.split("at mu = ")[1].split(";")[0])   # within the check's limit
    sim = Simulation(scene, team)
    n = compress(sim, mu)
    W0 = stored_energy(mu) * float(sim.points.volume[:n].sum())
    Watch(sim, tol=0.02, scale=W0).run(150)
    assert sim.energies().kinetic <= 1.02 * W0


@pytest.mark.parametrize("mu", [0.0042, 0.005, 0.0058])
def test_jh2_released_from_the_negative_tangent_range(team, mu):
    """Released from inside the range 0.0042 < mu < 0.0058 where dp/dmu < 0, at half
    the critical step."""
    release(team, mu)


def test_jh2_released_beyond_the_negative_tangent_range(team):
    """Released from mu = 0.015 (p = 0.33 GPa, falling to 0.03 GPa across the soft
    range) at half the critical step: the kinetic energy peaks at 0.83 of the stored
    energy.  (With the EOS at det F_mid, as before the fix, it gained 16 %.)"""
    release(team, 0.015)


def confined(dt_factor, steps, n=16, dx=1e-3, shell_layers=6):
    """A JH2 block whose outer 6 layers of points (two horizons) are fixed: compressed,
    it stays so.  Two horizons, because in the correspondence model a uniform stress
    is in equilibrium only at points whose neighbours all have complete families:
    near a surface (fixed or not) the truncated families give forces ~ p / delta."""
    L = n * dx
    t = shell_layers * dx
    shell = [((0, 0, 0), (t, L, L)), ((L - t, 0, 0), (L, L, L)), ((0, 0, 0), (L, t, L)),
             ((0, L - t, 0), (L, L, L)), ((0, 0, 0), (L, L, t)), ((0, 0, L - t), (L, L, L))]
    d = box_scene(JH2_PLAIN, dx, n, dt_factor, steps, initial=[
        {"kind": "velocity_pulse", "axis": "x", "center": L / 2, "half_width": L / 4,
         "velocity": [0.1, 0.0, 0.0]}])
    d["boundaries"] = [{"kind": "fixed", "region": {"lo": list(lo), "hi": list(hi)}}
                       for lo, hi in shell]
    return d


MU_FAR = 0.1


def far_dt(scene):
    """The step `mpipd check` says mu = 0.1 needs (its "EOS stiffening" line)."""
    line = [ln for ln in check_report(scene, 1).splitlines() if "EOS stiffening" in ln]
    assert line and f"at mu = {MU_FAR:g}" in line[0]
    return float(line[0].split("dt <= ")[1].split(" s")[0])


def jh2_pulse_block(factor, steps=2000, solver=None):
    L = 0.01
    return box_scene(JH2_PLAIN, 1e-3, 10, factor, steps, solver=solver, initial=[
        {"kind": "velocity_pulse", "axis": "x", "center": L / 2, "half_width": L / 4,
         "velocity": [0.1, 0.05, 0.0]}])


@pytest.mark.parametrize("factor,tol", [(0.23, 2e-2), (0.45, 2e-2), (0.9, 5e-2)])
def test_jh2_block_is_stable_over_long_runs(team, factor, tol):
    """A Table 1 JH2 block with a 0.1 m/s pulse, no failure reached, 2000 steps at
    0.23 (the built-in scenes' ratio), 0.45 and 0.9 of the critical step: the energy
    record's O((omega dt)^2) wobble, no growth.  The EOS takes det F_{n+1}; with
    det F_mid (before the fix) the pulse grew without bound at any of these."""
    sim = Simulation(make_scene(jh2_pulse_block(factor)), team)
    Watch(sim, tol=tol).run(2000, every=50)
    assert sim.failure_counts()[1:].sum() == 0


def held_far_beyond(team):
    mat = JH2()
    p = mat.bulk_modulus * MU_FAR + mat.K2 * MU_FAR ** 2 + mat.K3 * MU_FAR ** 3
    assert 250e9 < p < 260e9 and mat.K3 * MU_FAR ** 3 > 0.9 * p
    d = confined(0.5, 300)
    dt_needed = far_dt(make_scene(d))
    assert dt_needed < d["time"]["dt"] / 5
    d["time"]["dt"] = 0.9 * dt_needed
    sim = Simulation(make_scene(d), team)
    n = compress(sim, MU_FAR)
    w = Watch(sim, tol=2e-2, scale=sim.energies().kinetic).run(300, every=10)
    inner = sim.fixed[:n] == 0
    pressure = [g.state["pressure"] for g in sim.corr.groups][0]
    assert np.all(np.abs(pressure[inner] - p) < 0.01 * p)
    assert sim.failure_counts()[1:].sum() == 0 and w.worst <= 2e-2


def test_jh2_far_beyond_the_negative_tangent_range(team):
    """mu = 0.1: K3 mu^3 dominates, p = 257 GPa, and the P-wave speed is 61 km/s, 13 x
    the speed at rest.  A confined block (outer layers fixed) holds that compression.
    At 0.9 of the step `mpipd check` asks for at mu = 0.1 it is stable and holds
    Eq. 25's pressure (measured critical step: 0.080 dt_c, the check says 0.075)."""
    held_far_beyond(team)


def far_beyond_at_reference_step(team):
    d = confined(0.5, 300)
    sim = Simulation(make_scene(d), team)
    compress(sim, MU_FAR)
    return sim


def test_jh2_far_beyond_at_the_reference_step_blows_up(team):
    """At the step the reference moduli allow (0.5 dt_c, 6 x above the critical step
    at mu = 0.1) the run blows up within a few steps: velocities of ~1e5 m/s, the
    points around the blow-up fail, and the energy record leaves any bound.  The
    failure model zeroes their stresses before anything overflows, so no NaN
    appears: only the relative-speed check (|v_j - v_i| dt > |xi|) catches it."""
    sim = far_beyond_at_reference_step(team)
    e0 = sim.energies().kinetic
    for _ in range(60):
        sim.step()                                        # no checks on the way
    e = sim.energies()
    assert abs(e.total) > 1e6 * e0 and np.abs(sim.v).max() > 1e4
    assert sim.failure_counts()[1:].sum() > 100
    assert np.all(np.isfinite(sim.v)) and np.all(np.isfinite(sim.corr.sigma))
    with pytest.raises(Unstable, match=r"\|v_j - v_i\| dt > \|xi\|"):
        sim.check_finite()


def test_jh2_far_beyond_blow_up_is_reported(team):
    """The same run through Simulation.run stops with the point that ran away."""
    sim = far_beyond_at_reference_step(team)
    with pytest.raises(Unstable, match=r"\|v_j - v_i\| dt > \|xi\| at step"):
        sim.run(300)


def test_jh2_point_through_the_eos_range_and_back():
    """Hydrostatic load to mu = 0.1 and back through the negative-dp/dmu range: the
    pressure is Eq. 25 at every step (no drift through the soft range), finite,
    no damage, and zero again at mu = 0."""
    m = JH2()
    sig = np.zeros((1, 6))
    mode = np.zeros(1, np.uint8)
    st = m.new_state(1)
    idx = np.zeros(1, np.int64)
    mus = np.concatenate([np.linspace(0, 0.1, 2001), np.linspace(0.1, 0, 2001)[1:]])
    dt = 1e-8
    J_old = 1.0
    for mu in mus:
        J = 1.0 / (1.0 + mu)
        rate = math.log(J / J_old) / dt / 3.0
        m.update(idx, np.array([[rate, rate, rate, 0, 0, 0]]), np.array([J]), dt, sig, mode, st)
        J_old = J
        want = m.bulk_modulus * mu + m.K2 * mu * mu + m.K3 * mu ** 3
        assert np.all(np.isfinite(sig)) and mode[0] == 0
        assert -sig[0, 0] == pytest.approx(want, rel=1e-9, abs=1e-3)
    assert st["D"][0] == 0.0 and abs(sig[0, 0]) < 1e-3


# ----------------------------------------------------------------------------- JWL

def test_jwl_at_the_unreacted_density_and_at_huge_expansion():
    g = JWL()
    A, B, R1, R2, w, e0 = 568e9, 21.6e9, 5.81, 1.77, 0.282, 7.38e9
    assert g.pressure(1.0, e0) == pytest.approx(
        A * (1 - w / R1) * math.exp(-R1) + B * (1 - w / R2) * math.exp(-R2) + w * e0, rel=1e-14)
    for V in (10.0, 1e2, 1e4, 1e6, 1e9):
        p = g.pressure(V, e0)
        assert math.isfinite(p) and p > 0
        assert p == pytest.approx(w * e0 / V, rel=1e-3 if V >= 1e2 else 0.5)
    # along the CJ isentrope the energy left at V = 1e6 is tiny and positive
    cj = g.chapman_jouguet()
    C = g.isentrope_constant(cj["V"], cj["p"])
    assert 0 < g.isentrope_pressure(1e6, C) < 1e-3 * cj["p"]


def expand_freely(team, dt_factor):
    scene = free_charge(dt_factor=dt_factor, steps=int(round(60 / dt_factor)))
    sim = Simulation(scene, team)
    V0 = float(sim.gas.V0.sum())
    e_in = JWL().e0 * V0
    assert sim.energies().total == pytest.approx(e_in, rel=1e-12)
    gi = sim.gas.gas_idx
    p1 = JWL().pressure(1.0, JWL().e0)
    lit_p, worst = [], 0.0
    for _ in range(scene.time.n_steps):
        sim.step()
        if sim.step_count % 10 == 0:
            sim.check_finite()
            worst = max(worst, sim.energies().total / e_in - 1.0)
        # a point just fully lit burns at about the unreacted density: p near p(1, e0)
        just = ((sim.t >= sim.gas.t_lit + sim.gas.t_ramp)
                & (sim.t < sim.gas.t_lit + sim.gas.t_ramp + sim.dt))
        lit_p += list(sim.gas.gd[gi[just], 7] / p1)
    return sim, worst, lit_p


def test_unconfined_gas_expands_without_bound_stably(team):
    """A bare charge detonated from one end blows apart over 3 us: gas points reach
    V/V0 in the hundreds and lose their neighbourhoods (counted as singular: no
    force).  No NaN; the energy stays positive and finite; gas energy plus kinetic
    energy stays the released e0 V to round-off (the energy equation is the
    trapezoidal work of the gas's own forces, kernels.ul; the explicit e -= p_old dV
    it replaced gained 1.3 % here at dt = 0.3 dt_c, first order in dt)."""
    sim, worst, lit_p = expand_freely(team, 0.3)
    V = sim.gas.gd[sim.gas.gas_idx, 6] / sim.gas.V0
    assert V.max() > 50                                   # very large expansion reached
    assert np.all(np.isfinite(sim.gas.e)) and np.all(sim.gas.e > 0)
    assert sim.gas.n_singular > 0                         # isolated points, counted
    assert 0.5 < np.median(lit_p) < 1.5                   # burning at ~ the unreacted density
    assert abs(worst) < 1e-12                            # measured 4e-16
    assert abs(sim.energies().balance) < 1e-12


# ----------------------------------------------------------------------------- bonds

def test_too_few_bonds_fall_back_to_springs_and_are_counted(team, tmp_path):
    """A plate one lattice layer thick has a singular shape tensor everywhere: every
    point uses the bond-spring fallback, the count is reported, the run is stable."""
    dx = 1e-3
    d = {"scene": {"name": "plate"}, "time": {"dt": 1e-9, "steps": 200},
         "materials": {"m": {"model": "elastic", "density": 2660.0, "bulk_modulus": 21.9e9,
                             "shear_modulus": 25.7e9}},
         "parts": [{"name": "plate", "material": "m", "dx": dx,
                    "shape": {"kind": "box", "lo": [0, 0, 0], "hi": [0.02, 0.01, dx]}},
                   {"name": "block", "material": "m", "dx": dx,
                    "shape": {"kind": "box", "lo": [0.03, 0, 0], "hi": [0.04, 0.01, 0.01]}}],
         "solver": {"hourglass": 0.01},
         "initial": [{"kind": "velocity_pulse", "axis": "x", "center": 0.0, "half_width": 0.005,
                      "velocity": [1.0, 0.0, 0.0]}]}
    d["time"]["dt"] = 0.5 * critical_dt(make_scene(d))
    sim = Simulation(make_scene(d), team)
    assert sim.spring_points() == 20 * 10                 # the plate, not the block
    ke0 = sim.energies().kinetic
    Watch(sim, tol=1e-3).run(200)
    # the fallback springs' elastic energy is not in the energy record (solver gap,
    # reported), so the record can only fall below the input here
    assert sim.energies().kinetic <= ke0 * (1 + 1e-3)
    f = write_toml(tmp_path / "plate.toml", d)
    res = run_cli(["run", str(f), "--out", str(tmp_path / "o"), "--quiet"])
    assert res.returncode == 0, res.stderr
    assert "200 point(s) use the bond-spring fallback" in res.stdout


def granite_with_tension(**kw):
    m = {"model": "jh2", "tension": {"sigma_st": -6.9e6, "c1": 0.33, "rate0": 0.4}}
    m.update(kw)
    return m


def test_fully_crushed_zone_is_stable(team):
    """granite_ring (coarse) with its wall thrown out at 300 m/s: a fully crushed
    (phi = 1) zone at the wall, cracks beyond; stable, damage only grows, and the
    energy only falls (damping, failures)."""
    from mpipd.input import scene as sc
    scene, _ = sc.load("granite_ring", ["parts.0.dx=0.0015", "initial.0.speed=300",
                                        "time.t_end=8e-6"])
    sim = Simulation(scene, team)
    Watch(sim, tol=1e-3).run(scene.time.n_steps, every=10)
    counts = sim.failure_counts()
    n = sim.points.n_owned
    r = np.hypot(*sim.points.x[:n, :2].T)
    crushed = sim.failure.phi >= 1.0
    assert counts[1] > 50                                 # JH2 plastic failure (crushing)
    assert crushed[r < 0.006].mean() > 0.5                # the zone at the wall is crushed


def test_every_bond_broken(team):
    """A block torn apart by a homogeneous expansion (tension model, tiny strength):
    every point fails on the first steps, every bond breaks, every point is on the
    fallback with no bond left, and the pieces fly apart with constant kinetic energy."""
    m = {"model": "elastic", "density": 2660.0, "bulk_modulus": 21.9e9,
         "shear_modulus": 25.7e9, "tension": {"sigma_st": -1e3, "c1": 0.0, "rate0": 0.4}}
    d = box_scene(m, 1e-3, 8, 0.5, 60, solver={"hourglass": 0.01, "contact": True})
    sim = Simulation(make_scene(d), team)
    n = sim.points.n_owned
    c = sim.points.x[:n].mean(axis=0)
    sim.v[:n] = 1e3 * (sim.points.x[:n] - c)              # 1e3 1/s in every direction
    w = Watch(sim, tol=1e-3, scale=sim.energies().kinetic).run(60)
    assert np.all(sim.mode[:n] != 0)
    assert np.all(sim.families.broken == 1) and sim.bonds_broken() == sim.n_bonds_global
    assert np.all(sim.failure.phi == 1.0)
    assert sim.spring_points() == n
    ke = sim.energies().kinetic
    sim.run(sim.step_count + 20)
    assert sim.energies().kinetic == pytest.approx(ke, rel=1e-12)   # no force left
    assert w.worst <= 1e-3


# ----------------------------------------------------------------------------- strain rates

@pytest.mark.parametrize("rate", [1e5, 1e6])
def test_jh2_point_at_extreme_strain_rates(rate):
    """Pure shear at 1e5 and 1e6 1/s with the PD step: finite stress, strength with
    the rate term, D in [0, 1], and failure (mode 1) once D reaches 1."""
    m = JH2()
    sig = np.zeros((1, 6))
    mode = np.zeros(1, np.uint8)
    st = m.new_state(1)
    idx = np.zeros(1, np.int64)
    dt = 5e-8
    J = 1.0 / 1.002                                        # mu = 0.002, p > 0
    D_prev = 0.0
    for _ in range(2000):
        m.update(idx, np.array([[0, 0, 0, 0, 0, rate]]), np.array([J]), dt, sig, mode, st)
        assert np.all(np.isfinite(sig))
        assert D_prev <= st["D"][0] <= 1.0
        D_prev = st["D"][0]
        if mode[0]:
            break
    assert mode[0] == 1 and np.all(sig == 0.0)
    edot = 2 / math.sqrt(3) * rate
    assert st["strain_rate"][0] == pytest.approx(edot, rel=1e-12)


@pytest.mark.parametrize("rate", [1e5, 1e6])
def test_tension_model_at_extreme_strain_rates(rate):
    s = dynamic_strength(rate, -6.9e6, 0.33, 0.4)
    want = (rate / 0.4) ** 0.33 * -6.9e6
    assert s == pytest.approx(want, rel=1e-12) and math.isfinite(s)
    assert -1e9 < s < -6.9e6                               # 0.4-0.9 GPa: finite, stronger


@pytest.mark.parametrize("rate", [1e5, 1e6])
@pytest.mark.parametrize("kind", ["expansion", "shear"])
def test_jh2_block_at_extreme_strain_rates(team, rate, kind):
    """A JH2 + tension-model block given a homogeneous velocity field at 1e5 or 1e6 1/s
    (expansion, or simple shear): at the standard dt the strain per step is up to 5 %.
    Everything fails within a few steps; no NaN, energy never above the input,
    damage only grows."""
    d = box_scene(granite_with_tension(), 1e-3, 8, 0.5, 40,
                  solver={"hourglass": 0.01, "contact": True, "damping": 2e5,
                          "viscosity": {"cq": 8.0, "cl": 0.1}})
    sim = Simulation(make_scene(d), team)
    n = sim.points.n_owned
    x = sim.points.x[:n] - sim.points.x[:n].mean(axis=0)
    if kind == "expansion":
        sim.v[:n] = rate * x
    else:
        sim.v[:n, 0] = rate * x[:, 1]
    Watch(sim, tol=1e-3, scale=sim.energies().kinetic).run(40)
    assert sim.failure_counts()[1:].sum() > 0.5 * n


# ----------------------------------------------------------------------------- the blast
# The paper's 0.8 mm specimen blew up (issue 13): a rock point at r = 7.7 mm held
# -1590 J of stored work and moved at 34 km/s.  The same failure shows in a reduced
# demo at the paper's rock resolution: before the volume factor of
# Correspondence.rebuild_shape, this run (commit 3abcb55) ended at 8 us with 8 rock
# points below -1e7 J/m^3 (-2.97 J in all, min -7.3e8 J/m^3), a rock point at
# 537 m/s and 32 JH2 tensile failures; after it, none below zero, 59 m/s, 0.

# Run with the gas on the copper only (the paper's coupling, in which it was found and
# measured) and with the gas on the granite too (the scenes' default since 8ad176e):
# there the gas pushes the crushed rock at the wall directly (measured up to 384 m/s,
# at r0 = 3.6-5.6 mm, every such point failed; 74 m/s beyond two horizons of the wall).
# The scene's integration: ratio 4 since blast_demo steps so (the figures below give
# both, measured on this reduction with time.multirate={max_ratio=1} and without).
# Both under the scenes' model of then (Eq. 25's pressure, no gas-solid contact or wall: the case
# previous_model), in which they were measured.
_THEN = ['materials.granite.pressure="eos"', "materials.explosive.contact=false",
         "materials.explosive.wall=false"]
COUPLING = {"paper": ['materials.explosive.interacts_with=["copper"]'] + _THEN,
            "contained": ['materials.explosive.interacts_with=["copper", "granite"]'] + _THEN}


@pytest.fixture(scope="module", params=sorted(COUPLING))
def blast_08(team, request):
    from mpipd.input import scene as sc
    from mpipd.model.ledger import impossible
    # the rock cut to r = 15 mm: probe C (25.2 mm) moves inside it
    scene, _ = sc.load("blast_demo", ["parts.2.dx=8e-4", "parts.2.shape.radius=0.015",
                                      "probes.3.position=[0.0145, 0.0, 0.003]",
                                      "time.t_end=8e-6"] + COUPLING[request.param])
    sim = Simulation(scene, team)
    worst = 0.0
    for _ in range(scene.time.n_steps):
        sim.step()
        if sim.step_count % 20 == 0:
            e = sim.energies()
            worst = max(worst, abs(e.balance))
            assert not impossible(e), impossible(e)
    return sim, sim.energies(), worst, request.param


# The two cases of the model of then run for minutes each (serial, in process); since
# the scenes hold the gas with the wall (notes §51) they guard a superseded
# configuration and moved to the long tier (make stability), keeping make test under
# its 20 minutes
@pytest.mark.long
def test_blast_at_the_paper_rock_resolution_stays_physical(blast_08):
    sim, e, _, coupling = blast_08
    n = sim.points.n_owned
    W = sim.corr.W
    # no negative stored work of any size: the bug this guards against left -7.3e8 J/m^3
    # (-3.6 x the largest W); since the spring-fallback fix (30f82fc) the contained run
    # ends with 4 failed points at -9.5e3 J/m^3 (-3.9e-5 x), the trapezoidal rule's
    # error on a point unloaded before it failed (booked with it in ``removed``)
    assert W.min() > -1e-4 * W.max()
    speed = np.linalg.norm(sim.v[:n], axis=1)
    rock = sim.points.material[:n] == list(sim.scene.materials).index("granite")
    x = sim.points.x[:n]
    r0 = np.hypot(x[:, 0], x[:, 1])
    wall = sim.scene.parts[2].shape.inner_radius
    if coupling == "paper":
        assert speed[rock].max() < 200.0                 # 60 m/s single-rate (537 before), 60 at ratio 4
    else:                                               # the gas drives the wall layer
        far = rock & (r0 > wall + 2 * sim.scene.parts[2].horizon)
        assert speed[far].max() < 200.0                  # 73 m/s single-rate, 68 at ratio 4
        fast = rock & (speed > 200.0)                   # inside the crushed zone
        assert fast.any() and np.all(sim.mode[:n][fast] > 0)
    assert speed[rock].max() < speed[sim.gas.gas_idx].max()
    assert sim.failure_counts()[2] == 0                  # no JH2 tensile artefacts (32 before)


@pytest.mark.long
def test_blast_ledger_closes(blast_08):
    from conftest import closure_without
    sim, e, worst, _ = blast_08
    assert worst < 1e-4                                  # 1.2e-5, 1.8e-5 single-rate; 1.1e-5, 1.7e-5 at ratio 4
    assert e.gas_damping > 0 and e.plastic > 0 and e.kinetic > 0.3 * e.initial
    for term in ("gas_damping", "gas", "plastic", "removed", "contact"):
        assert closure_without(e, term) > 1e-4, term


# ------------------------------------------------------------------ the paper's geometry
# Issue 15: `blast_paper:dx1.2` stopped at step 430 (8.6 us) with copper tube points at
# r = 2.85-3.18 mm moving at up to 2.5e22 m/s.  This reduction of it (the rock cut to
# r = 40 mm, 12 us; 180,692 points) blew up at the same step and point.  It is kept
# here at the paper's three resolutions, on 2 ranks, as `make stability` runs it.
#: the scenes' model before issue 60 (the case previous_model), in which the reductions
#: below were found and measured, as overrides after a case's own
PREVIOUS = ["--set", 'materials.granite.pressure="eos"',
            "--set", 'materials.explosive.interacts_with=["copper", "granite"]',
            "--set", "materials.explosive.contact=false"]
#: the former case gas_contact: the gas on the copper and the granite, with the contact
GAS_CONTACT_THEN = ["blast_paper:gas_contact", "--set", 'materials.granite.pressure="eos"',
                    "--set", 'materials.explosive.interacts_with=["copper", "granite"]']
PAPER_REDUCED = ["blast_paper:dx1.2", *PREVIOUS, "--set", "parts.2.shape.radius=0.040",
                 "--set", "time.t_end=1.2e-5", "--set", "output.every=100",
                 "--set", "output.checkpoint_every=600",
                 # probes E-G (42.8-62.8 mm) lie outside the cut rock: move them inside
                 "--set", "probes.5.position=[0.0350, 0.0, 0.0004]",
                 "--set", "probes.6.position=[0.0370, 0.0, 0.0004]",
                 "--set", "probes.7.position=[0.0390, 0.0, 0.0004]"]


def run_reduced(tmp_path, args):
    """Run a reduced paper scene on 2 ranks, as `make stability` does: its output
    folder and, from its run file, the copper mask, x, the last frame's u, every
    step's peak speed over the run and the ledger (which must be possible)."""
    import h5py

    from mpipd.model.ledger import Energies, impossible
    out = tmp_path / "run"
    res = run_cli(["run", *args, "--out", str(out), "--quiet"], ranks=2, timeout=3600)
    assert res.returncode == 0, res.stdout + res.stderr
    with h5py.File(out / "run.h5", "r") as f:
        names = list(f["geometry/material"].attrs["names"])
        got = {"cu": f["geometry/material"][...] == names.index("copper"),
               "x": f["geometry/x"][...], "u": f["fields/u"][-1],
               "peak": f["fields/peak_speed"][-1], "e": Energies.from_record(f["energy"]),
               "spring": f["energy/spring"][...], "removed": f["energy/removed"][...]}
    assert not impossible(got["e"]), impossible(got["e"])
    assert np.all(np.isfinite(got["peak"]))
    return out, got


@pytest.mark.long
def test_paper_geometry_at_dx_1_2_runs_through_the_copper_blow_up(tmp_path):
    import h5py
    out, got = run_reduced(tmp_path, PAPER_REDUCED)
    cu = got["cu"]
    with h5py.File(out / "checkpoint.h5", "r") as f:
        assert int(f.attrs["step"]) == 600
        spring = f["points/spring"][...]
        pairs = f["broken"][...]
    assert abs(got["e"].balance) < 1e-3
    # the tube: no point near the astronomical speeds of the blow-up, and none of its
    # own bonds broken (copper has no failure model here; rock failures break only
    # bonds with an end in the rock, kernels.breakage)
    assert got["peak"][cu].max() < 1000.0
    assert not np.any(cu[pairs[:, 0]] & cu[pairs[:, 1]])
    assert np.count_nonzero(spring[cu] != 0) < 0.01 * np.count_nonzero(cu)


# Issue 15, the gas-solid contact: `blast_paper:gas_contact` at dx 1.2 mm stopped at
# step 800 (16 us) in the copper tube (stop 33).  This reduction of it (the rock cut
# to r = 40 mm, no probes) stopped at the same step at dt = 2e-8 s, ratio 4, with
# the classes taken at rest (runs/r40_contact_ctl at 19b1ac2: "relative speed
# |v_j - v_i| dt > |xi| at step 800", gid 36338, a tube point at r = 4.6 mm).  The
# gas kept inside drives the tube to 2.4 x its radius by 12 us and thins it to a
# quarter of its spacing; the case now halves dt at max_ratio 8 and the classes
# follow the thinned spacing (mpipd.model.multirate, lambda_min).  It keeps that
# dt, 1e-8 s, at which its figures were measured; the case has since gone to 5e-9 s
# for the 0.8 mm rock (the test after it).
CONTACT_REDUCED = [*GAS_CONTACT_THEN, "--set", "parts.2.dx=1.2e-3",
                   "--set", "parts.2.shape.radius=0.040", "--set", "probes=[]",
                   "--set", "time.dt=1.0e-8",
                   "--set", "time.t_end=1.8e-5", "--set", "output.every=200",
                   "--set", "output.checkpoint_every=1800"]


@pytest.mark.long
def test_paper_geometry_with_the_gas_contact_runs_past_the_thinned_tube(tmp_path):
    _, got = run_reduced(tmp_path, CONTACT_REDUCED)
    cu, x, u = got["cu"], got["x"], got["u"]
    assert abs(got["e"].balance) < 2e-4                # measured +6.2e-5 at 18 us
    # past the thinning: the tube is stretched beyond 2.4 x its radius somewhere
    r0 = np.hypot(x[cu, 0], x[cu, 1])
    r = np.hypot(x[cu, 0] + u[cu, 0], x[cu, 1] + u[cu, 1])
    assert (r / r0).max() > 2.4                        # measured 2.92
    assert got["peak"][cu].max() < 1500.0              # measured 1136 m/s


# Issue 15 (studies/validation/notes.md §41): `blast_paper:gas_contact` at the paper's
# 0.8 mm rock stopped at step 2580 (25.8 us) at dt = 1e-8 s with non-finite u in the
# tube near the detonation face.  This reduction of it (all parts cut to z = 0-25 mm,
# the rock to r = 20 mm, no probes; 77,292 points) stopped at step 2560 (25.6 us) in the
# same place: the tube, blown out to 4.2 x its radius by 24 us, has its wall thinned to
# 0.11 of its thickness (principal stretches 0.11, 2.5, 3.6 at 20 us in both), and its
# correspondence force went unstable (copper speeds 530 -> 8200 m/s between 25.3 and
# 25.5 us).  The case now steps at dt = 5e-9 s with max_ratio 8.
def cut_25mm(case, rock_radius, t_end, every, checkpoint_every):
    """The arguments of a paper case with all three parts cut to z = 0-25 mm and the
    rock to ``rock_radius``, without probes."""
    args = list(case) if isinstance(case, list) else [case]
    for k in range(3):
        args += ["--set", f"parts.{k}.shape.z=[0.0, 0.025]"]
    return args + ["--set", f"parts.2.shape.radius={rock_radius}", "--set", "probes=[]",
                   "--set", f"time.t_end={t_end}", "--set", f"output.every={every}",
                   "--set", f"output.checkpoint_every={checkpoint_every}"]


CONTACT_08_REDUCED = cut_25mm(GAS_CONTACT_THEN, "0.020", "3.0e-5", 400, 6000)


@pytest.mark.long
def test_paper_geometry_gas_contact_at_the_papers_rock_runs_past_the_thinned_tube(tmp_path):
    _, got = run_reduced(tmp_path, CONTACT_08_REDUCED)
    cu, x, u = got["cu"], got["x"], got["u"]
    assert abs(got["e"].balance) < 1e-4                # measured +4.3e-5 at 30 us
    assert got["removed"].min() >= 0.0
    assert got["spring"].max() < 0.01                   # measured 4e-6 J
    r0 = np.hypot(x[cu, 0], x[cu, 1])
    r = np.hypot(x[cu, 0] + u[cu, 0], x[cu, 1] + u[cu, 1])
    assert (r / r0).max() > 4.0                        # past the thinning: measured 4.45
    assert got["peak"][cu].max() < 1500.0              # measured 989 m/s


# Issue 15 (studies/validation/notes.md §39-40): `blast_paper:seamless` stopped at step 800
# (16 us) with its ledger's `removed` at -183 J: copper tube points near the detonation
# face, blown out to 2.3-2.5 x the tube's radius, whose F turned singular took the bond
# springs, which measured their stretch from the reference and so held 21-32 J each.
# This reduction of it (the rock cut to r = 15 mm and all parts to 25 mm, no probes;
# 296,200 points) failed at the same step and places with 501ccb2's mpipd/ (11 copper
# points on the singular-F springs holding 314 J, then |v_j - v_i| dt > |xi|).  The
# springs now stretch from the configuration the point had when it switched
# (kernels.nosb, the spring reference map), but that alone did not carry it through:
# stepped one by one from step 700, the tube's correspondence force went unstable
# from step 761 (speeds 309 -> 1356 m/s and the balance 2e-5 -> 1.4e-3 by step 786)
# before any point took the springs.  The band's rock gives way, and the tube, blown
# out to 2.1-2.7 x its radius, thins beyond the paper's dt; the case now halves dt at
# max_ratio 8 (studies/validation/notes.md §40).
SEAMLESS_REDUCED = cut_25mm(["blast_paper:seamless", *PREVIOUS], "0.015", "2.0e-5", 200, 2000)


@pytest.mark.long
def test_paper_geometry_seamless_tube_on_the_springs_stays_booked(tmp_path):
    _, got = run_reduced(tmp_path, SEAMLESS_REDUCED)
    assert abs(got["e"].balance) < 1e-4                # measured +6.3e-6 at 20 us
    assert got["removed"].min() >= 0.0                  # nothing made and booked as removed
    assert got["spring"].max() < 0.01                   # measured 6e-5 J (314 J before)
    assert got["peak"][got["cu"]].max() < 1000.0        # measured 458 m/s


# Issue 15/17 (studies/validation/notes.md §26): blast_demo's jittered rock (seed 3) blew
# up single-rate at step 530 at dt = 2 us / 96 (and at step 1360 at 2 us / 120), and at
# ratio 4 at the scene's dt at step 400: intact correspondence points with 3-5 bonds
# left and a near-singular K (|K^-1| up to 1e26) that passed the RCOND test.  Such a
# point now takes the bond springs once its shape tensor's stable step falls below dt
# (mpipd.model.correspondence.stable_floor).  Both runs go well past their blow-up.
JITTER = ["blast_demo:jitter", *PREVIOUS, "--set", "parts.2.jitter_seed=3", "--set", "output.every=100"]
JITTER_RUNS = {
    "single_rate_1.04dt": ["--set", "time.multirate={max_ratio=1}",
                           "--set", "time.dt=2.0833333333333334e-08",
                           "--set", "time.t_end=1.4583333333333334e-05",
                           "--set", "output.checkpoint_every=700"],
    "ratio4": ["--set", "time.multirate={max_ratio=4, safety=0.5}",
               "--set", "time.t_end=1.2e-05", "--set", "output.checkpoint_every=600"]}


@pytest.mark.long
@pytest.mark.parametrize("run", list(JITTER_RUNS))
def test_jittered_rock_with_near_singular_shape_tensors_runs_through(tmp_path, run):
    import h5py
    out, got = run_reduced(tmp_path, JITTER + JITTER_RUNS[run])
    steps = {"single_rate_1.04dt": 700, "ratio4": 600}[run]
    with h5py.File(out / "checkpoint.h5", "r") as f:
        assert int(f.attrs["step"]) == steps
    with h5py.File(out / "run.h5", "r") as f:
        names = list(f["geometry/material"].attrs["names"])
        rock = f["geometry/material"][...] == names.index("granite")
    assert abs(got["e"].balance) < 1e-3
    assert got["peak"][rock].max() < 1000.0
    log = (out / "run.log").read_text()
    switched = re.search(r"(\d+) such switch\(es\) from the correspondence force", log)
    assert switched and int(switched.group(1)) > 0, log                # the test acted


# Issue 15 (studies/validation/notes.md §34): `blast_paper:paper_coupling` ran to t_end but
# its ledger broke at 14-16 us (balance -0.37, then -0.48): four force-free gas points
# coasting onto the charge's axis met there, their family compressed them 100-fold in
# one step and they left at 100-190 km/s with 3.5 kJ unbooked.  This reduction of it
# (the rock cut to r = 12 mm, 76,708 points, 800 steps; about 2.5 minutes on 2 ranks)
# did the same at the same time (balance -0.40, gas peak speed 183 km/s with ed91c1a's
# mpipd/).  A family that collapses in a step now carries no force
# (mpipd.kernels.ul.MAX_VOLUME_STRAIN): balance -1.7e-5, gas peak speed 6.6 km/s.
COUPLING_REDUCED = ["blast_paper", "--set", 'materials.granite.pressure="eos"',
                    "--set", "parts.2.shape.radius=0.012",
                    "--set", "probes=[]", "--set", "time.t_end=1.6e-5",
                    "--set", "output.every=200", "--set", "output.checkpoint_every=800"]


@pytest.mark.long
def test_paper_coupling_gas_meeting_on_the_axis_stays_booked(tmp_path):
    import h5py
    out, got = run_reduced(tmp_path, COUPLING_REDUCED)
    with h5py.File(out / "run.h5", "r") as f:
        names = list(f["geometry/material"].attrs["names"])
        gas = f["geometry/material"][...] == names.index("explosive")
    assert abs(got["e"].balance) < 1e-4                 # measured -1.7e-5 (-0.40 before)
    assert got["peak"][gas].max() < 10_000.0            # 6.6 km/s (183 km/s before)
