"""The explosive gas (paper §2.6): programmed detonation, JWL pressure, energy
bookkeeping, parallel consistency, and who interacts with whom."""
import math

import h5py
import numpy as np
import pytest
from conftest import restart_matches, run_cli

from mpipd.input import scene as sc
from mpipd.solver import Simulation

VOD = 6690.0
SMALL = ["--set", "parts.2.shape.radius=0.006", "--quiet",
         "--set", 'output.fields=["u","v","pressure"]']


@pytest.fixture(scope="module")
def det_runs(tmp_path_factory):
    base = tmp_path_factory.mktemp("det")
    out = {}
    for n in (1, 2, 3):
        res = run_cli(["run", "detonation_tube", "--out", str(base / f"n{n}"), *SMALL],
                      ranks=n, timeout=600)
        assert res.returncode == 0, res.stdout + res.stderr
        out[n] = base / f"n{n}" / "run.h5"
    return out


def front_positions(f, threshold=2e9):
    """Axial position where the gas pressure on the axis crosses ``threshold``
    (linear interpolation between lattice levels), per frame."""
    x = f["geometry/x"][...]
    mat = f["geometry/material"][...]
    axis = (mat == 0) & (np.hypot(x[:, 0], x[:, 1]) < 1.2e-3)
    zs = np.unique(x[axis, 2])
    p = f["fields/pressure"][...]
    out = []
    for k in range(len(p)):
        prof = np.array([p[k, axis][x[axis, 2] == z].mean() for z in zs])
        above = np.flatnonzero(prof > threshold)
        if not len(above) or above.max() + 1 >= len(zs):
            out.append(np.nan)
            continue
        a = above.max()
        out.append(zs[a] + (prof[a] - threshold) / (prof[a] - prof[a + 1]) * (zs[a + 1] - zs[a]))
    return f["time"][...], np.array(out)


def test_detonation_front_moves_at_vod_across_slabs(det_runs):
    with h5py.File(det_runs[2], "r") as f:          # 2 ranks: the front crosses z = 8 mm
        t, z = front_positions(f)
    ok = np.isfinite(z) & (z > 0.003) & (z < 0.013)
    assert ok.sum() >= 8
    speed = np.polyfit(t[ok], z[ok], 1)[0]
    assert abs(speed - VOD) / VOD < 0.01, speed


def test_detonation_identical_on_1_2_3_ranks(det_runs):
    with h5py.File(det_runs[1], "r") as f1:
        ref = {k: f1[k][...] for k in ("fields/u", "fields/v", "fields/pressure")}
    for n in (2, 3):
        with h5py.File(det_runs[n], "r") as f:
            for k, a in ref.items():
                assert np.array_equal(f[k][...], a), f"{k} differs between 1 and {n} ranks"


def test_energy_bookkeeping(det_runs):
    """The ledger of the detonation (gas, copper, rock): its initial energy is the
    chemical energy e0 times the charge volume, and what is held plus what was
    dissipated stays equal to it (|balance| measured 1e-5 at this resolution)."""
    with h5py.File(det_runs[1], "r") as f:
        e = f["energy"]
        mat = f["geometry/material"][...]
        V = f["geometry/volume"][...]
        released = 7.38e9 * V[mat == 0].sum()
        assert e["gas"][0] == pytest.approx(released, rel=1e-12)
        assert e["initial"][0] == pytest.approx(released, rel=1e-12)
        assert e["kinetic"][-1] > 0.2 * released            # a real blast happened
        assert np.abs(e["balance"][...]).max() < 1e-4
    with h5py.File(det_runs[3], "r") as f:                 # and on 3 ranks alike
        assert np.abs(f["energy/balance"][...]).max() < 1e-4


def test_jwl_pressure_at_unreacted_density(team):
    """Lit everywhere (a late time) and still at rest: p = JWL(V_R = 1, e0), Table 2."""
    scene, _ = sc.load("detonation_tube", ["parts.0.shape.z=[0.0, 0.004]",
                                           "parts.1.shape.z=[0.0, 0.004]",
                                           "parts.2.shape.z=[0.0, 0.004]"])
    sim = Simulation(scene, team)
    sim.gas.update(sim.u, sim.v, scene.time.dt, 1.0)
    g = sim.gas
    p = g.gd[g.gas_idx, 7]
    A, B, R1, R2, w, e0 = 568e9, 21.6e9, 5.81, 1.77, 0.282, 7.38e9
    want = A * (1 - w / R1) * math.exp(-R1) + B * (1 - w / R2) * math.exp(-R2) + w * e0
    np.testing.assert_allclose(p, want, rtol=1e-12)


@pytest.mark.parametrize("lit", [False, True])
def test_an_unlit_charge_resists_compression_with_its_hugoniot(team, lit):
    """A uniform compression rate v = -a x over the charge, tube and rock (an affine
    field: tr L = -3a exactly at every gas point with a full family): after one step,
    V_R = exp(-3a dt).  Unlit (t < 0) the pressure is the unreacted Hugoniot's,
    rho0 c0^2 eta / (1 - s eta)^2 with eta = 1 - V_R, and e gains the trapezoidal work
    p b / 2 (b = -3a dt per initial volume); without an unreacted EOS the unlit charge
    carries nothing, and once lit (lam = 1) the pressure is JWL's alone."""
    c0, s_h, a = 2300.0, 2.0, 2.0e5
    sets = ["parts.0.shape.z=[0.0, 0.004]", "parts.1.shape.z=[0.0, 0.004]",
            "parts.2.shape.z=[0.0, 0.004]"]
    out = {}
    for name, extra in (("bare", []), ("unreacted",
                                       [f"materials.explosive.unreacted={{c0={c0}, s={s_h}}}"])):
        scene, _ = sc.load("detonation_tube", sets + extra)
        sim = Simulation(scene, team)
        dt = scene.time.dt
        if a == "cap":
            a = 0.45 / (3.0 * dt)
        sim.v[:] = -a * sim.points.x
        sim.gas.update(sim.u, sim.v, dt, 1.0 if lit else -1.0)
        g = sim.gas
        full = g.offsets[g.gas_idx + 1] - g.offsets[g.gas_idx] >= 30     # interior points
        out[name] = (g.gd[g.gas_idx, 7][full], g.e[full], (g.gd[g.gas_idx, 6] / g.V0)[full])
        # the density at lighting is kept from the step a point is lit
        vr_all = g.gd[g.gas_idx, 6] / g.V0
        if lit:
            np.testing.assert_array_equal(g.vr_lit, vr_all)
            d = g.lit_density(team)["charge"]
            assert d["max"] == pytest.approx(1.0 / vr_all.min()) and d["lit_fraction"] == 1.0
        else:
            assert (g.vr_lit == 0.0).all()
    VR = math.exp(-3.0 * a * dt)
    p_bare, e_bare, vr = out["bare"]
    p_u, e_u, vr_u = out["unreacted"]
    assert len(vr) > 50
    np.testing.assert_allclose(vr, VR, rtol=1e-12)
    np.testing.assert_allclose(vr_u, VR, rtol=1e-12)
    if not lit:
        eta = 1.0 - VR
        want = 1320.0 * c0 ** 2 * eta / (1.0 - s_h * eta) ** 2
        assert want > 1e6
        np.testing.assert_allclose(p_u, want, rtol=1e-9)
        np.testing.assert_allclose(e_u, 7.38e9 + 0.5 * want * 3.0 * a * dt, rtol=1e-12)
        assert np.all(p_bare == 0.0) and np.all(e_bare == 7.38e9)
    else:
        np.testing.assert_array_equal(p_u, p_bare)
        np.testing.assert_array_equal(e_u, e_bare)


def test_a_porous_charge_compacts_freely_then_follows_the_solid_hugoniot():
    """PETN at 1320 kg/m^3 over a solid of 1760 (Saenz & Stewart 2008: c0 2300 m/s,
    s 2.5): no pressure until V_R = 1320/1760 = 0.75; below it the solid's Hugoniot
    pressure rho_s U_s u_p, with u_p = eta U_s (mass balance) and U_s = c0 + s u_p, i.e.
    u_p = c0 eta / (1 - s eta), computed here from the shock relations; the scene's
    unreacted table gives the kernel's (K, s, a)."""
    from mpipd.materials.jwl import unreacted_pressure
    scene, _ = sc.load("blast_bench", [
        "materials.explosive.unreacted={c0=2300.0, s=2.5, solid_density=1760.0}"])
    K, s_h, a = scene.materials["explosive"].unreacted_eos
    assert K == pytest.approx(1760.0 * 2300.0 ** 2) and s_h == 2.5 and a == pytest.approx(1760.0 / 1320.0)
    for VR in (1.2, 1.0, 0.9, 0.76, 0.75):
        assert unreacted_pressure(VR, K, s_h, a) == 0.0
    for VR in (0.74, 0.72, 0.70, 0.65):
        eta = 1.0 - 1760.0 / (1320.0 / VR)          # 1 - rho_s / rho
        up = 2300.0 * eta / (1.0 - 2.5 * eta)
        us = 2300.0 + 2.5 * up
        assert unreacted_pressure(VR, K, s_h, a) == pytest.approx(1760.0 * us * up, rel=1e-12)
    assert unreacted_pressure(0.7, 0.0, 2.5, a) == 0.0                 # no unreacted EOS
    with pytest.raises(sc.SceneError, match="solid_density"):
        sc.load("blast_bench", ["materials.explosive.unreacted={c0=2300.0, solid_density=1000.0}"])


VISC = "materials.explosive.viscosity={quadratic=1.5, linear=0.06}"


def isentrope_c2(VR, p, rho0=1320.0):
    """c^2 = -(VR^2 / rho0) dp_s/dVR along the JWL isentrope through (VR, p), by a
    central difference of JWL.isentrope_pressure (Table 2 constants)."""
    from mpipd.materials.jwl import JWL
    j = JWL()
    C = j.isentrope_constant(VR, p)
    h = 1e-6 * VR
    dp = (j.isentrope_pressure(VR + h, C) - j.isentrope_pressure(VR - h, C)) / (2 * h)
    return -VR * VR / rho0 * dp


@pytest.mark.parametrize("a", [2.0e5, -2.0e5, "cap"])
def test_bulk_viscosity_of_a_uniformly_compressed_charge(team, a):
    """v = -a x, lit: tr L = -3a at every interior gas point.  Compressed (a > 0), q =
    rho l (1.5 l (3a)^2 + 0.06 c 3a) with rho = rho0 / V_R, l = the charge's dx and c from the JWL
    isentrope through (V_R, p) (a finite difference here); the pressure p and the energy
    are those of the run without viscosity, the force state is -(p + q) M^-1, and the
    work taken out is sum q |b| / 2 (b = V 3a dt).  At |tr L| dt = 0.45 ("cap": 1.5
    |tr L| dt = 0.675 > 1/2, within the kernel's MAX_VOLUME_STRAIN = 0.5) q is held to
    rho l^2 |tr L| / (2 dt).  Expanding (a < 0): no q."""
    sets = ["parts.0.shape.z=[0.0, 0.004]", "parts.1.shape.z=[0.0, 0.004]",
            "parts.2.shape.z=[0.0, 0.004]"]
    out = {}
    for name, extra in (("bare", []), ("visc", [VISC])):
        scene, _ = sc.load("detonation_tube", sets + extra)
        sim = Simulation(scene, team)
        dt = scene.time.dt
        if a == "cap":
            a = 0.45 / (3.0 * dt)
        sim.v[:] = -a * sim.points.x
        sim.gas.update(sim.u, sim.v, dt, 1.0)
        g = sim.gas
        full = g.offsets[g.gas_idx + 1] - g.offsets[g.gas_idx] >= 30
        out[name] = (g.gd[g.gas_idx][full], g.gq[full], g.e[full], g.viscous_work, g.V0[full])
        dx = scene.parts[0].dx
    gd0, _, e0, _, _ = out["bare"]
    gd1, q, e1, work, V0 = out["visc"]
    assert len(q) > 50
    np.testing.assert_array_equal(gd1[:, 7], gd0[:, 7])          # p: the EOS's alone
    np.testing.assert_array_equal(e1, e0)
    VR = math.exp(-3.0 * a * dt)
    ell = np.cbrt(V0)
    np.testing.assert_allclose(ell, dx, rtol=1e-12)             # the charge's dx
    if a < 0:
        assert np.all(q == 0.0) and work == 0.0
        np.testing.assert_array_equal(gd1, gd0)
        return
    p = gd0[:, 7]
    rho, trL = 1320.0 / VR, -3.0 * a
    c = np.sqrt([isentrope_c2(VR, pk) for pk in p])
    want = rho * ell * (1.5 * ell * trL ** 2 - 0.06 * c * trL)
    cap = 0.5 * rho * ell ** 2 * (-trL) / dt
    if a > 1e7:
        assert np.all(want > cap)
        np.testing.assert_allclose(q, cap, rtol=1e-12)
    else:
        assert np.all(want < cap) and want.min() > 1e7
        np.testing.assert_allclose(q, want, rtol=1e-6)
    np.testing.assert_allclose(gd1[:, :6], gd0[:, :6] * ((p + q) / p)[:, None], rtol=1e-12)
    assert work > 0.0


def test_bulk_viscosity_is_booked_and_survives_a_restart_on_another_rank_count(tmp_path):
    """The detonation with the gas viscosity: the ledger closes with gas_viscous > 0, and
    a run stopped on 2 ranks and continued on 3 is the 1-rank run bit for bit (the
    checkpoint keeps each point's last q and the dissipated work)."""
    args = ["run", "detonation_tube", *SMALL, "--set", VISC, "--set", "time.t_end=1.2e-6"]
    ref, d = tmp_path / "one", tmp_path / "r"
    res = run_cli(args + ["--out", str(ref)], ranks=1, timeout=600)
    assert res.returncode == 0, res.stdout + res.stderr
    res = run_cli(args + ["--out", str(d), "--stop-after", "40"], ranks=2, timeout=600)
    assert res.returncode == 0, res.stdout + res.stderr
    restart_matches(d / "checkpoint.h5", ref / "run.h5",
                    ("fields/u", "fields/v", "fields/pressure"), ranks=3, timeout=600)
    with h5py.File(ref / "run.h5", "r") as f1, h5py.File(d / "run.h5", "r") as f:
        e = f1["energy"]
        assert e["gas_viscous"][-1] > 0.0 and np.all(np.diff(e["gas_viscous"][...]) >= 0.0)
        assert np.abs(e["balance"][...]).max() < 1e-5
        np.testing.assert_allclose(f["energy/gas_viscous"][...], e["gas_viscous"][...],
                                   rtol=1e-12)


def test_a_negative_viscosity_coefficient_is_refused():
    with pytest.raises(sc.SceneError, match="quadratic"):
        sc.load("detonation_tube", ["materials.explosive.viscosity={quadratic=-1.0}"])
    with pytest.raises(sc.SceneError, match="lin"):
        sc.load("detonation_tube", ["materials.explosive.viscosity={lin=0.1}"])


def test_the_gas_is_its_own_model_family(team):
    """The explosive is the "ul" model (mpipd.model.gas), built from the scene beside
    the correspondence solids: no material group, history or stress update of the
    correspondence machinery holds it, and its points carry the NOT_TL code."""
    from mpipd.kernels.layout import NOT_TL
    from mpipd.model.correspondence import Correspondence
    from mpipd.model.gas import Gas
    scene, _ = sc.load("detonation_tube", ["parts.2.shape.radius=0.005"])
    sim = Simulation(scene, team)
    assert [type(m) for m in sim.models] == [Correspondence, Gas] and sim.gas is sim.models[1]
    names = list(scene.materials)
    ex = names.index("explosive")
    assert ex not in {g.mid for g in sim.corr.groups}
    assert not any(k.startswith(f"state{ex}/") for k in sim.state.fields)
    n = sim.points.n_owned
    assert np.all(sim.corr.spring[sim.gas.gas_idx] == NOT_TL)
    assert len(sim.gas.gas_idx) == np.count_nonzero(sim.points.material[:n] == ex)
    # a scene without an explosive builds the solids' model alone
    solid, _ = sc.load("granite_ring", [])
    assert [type(m) for m in Simulation(solid, team).models] == [Correspondence]


def test_gas_has_no_bonds_and_does_not_touch_rock(team):
    scene, _ = sc.load("detonation_tube", ["parts.2.shape.radius=0.005"])
    sim = Simulation(scene, team)
    p, fam = sim.points, sim.families
    gas = sim.gas.is_gas.astype(bool)
    rows = np.repeat(np.arange(p.n_owned), np.diff(fam.offsets))
    assert not gas[rows].any() and not gas[fam.nbr].any()        # no TL bond touches gas
    sim.gas.search(sim.points.x + sim.u, sim.v)
    g = sim.gas
    ul_rows = np.repeat(np.arange(p.n_owned), np.diff(g.offsets))
    names = list(scene.materials)
    rock = p.material == names.index("granite")
    assert not rock[ul_rows].any() and not rock[g.nbr].any()     # no gas-rock bonds
    copper = p.material == names.index("copper")
    assert copper[g.nbr].any()                                   # the gas loads the copper


def test_restart_through_the_detonation(tmp_path, det_runs):
    """Stopped mid-detonation on 2 ranks, continued on 3: the 1-rank run, bit for bit."""
    d = tmp_path / "r"
    res = run_cli(["run", "detonation_tube", "--out", str(d), "--stop-after", "70", *SMALL],
                  ranks=2)
    assert res.returncode == 0, res.stderr
    res = run_cli(["run", "--restart", str(d / "checkpoint.h5"), "--quiet"], ranks=3)
    assert res.returncode == 0, res.stdout + res.stderr
    with h5py.File(det_runs[1], "r") as f1, h5py.File(d / "run.h5", "r") as f:
        for k in ("fields/u", "fields/v", "fields/pressure"):
            assert np.array_equal(f[k][...], f1[k][...]), k
        # a global sum: equal up to the order of the reduction
        np.testing.assert_allclose(f["energy/gas"][...], f1["energy/gas"][...], rtol=1e-12)
        # the every-step peak and the density at lighting are the whole run's
        assert f.attrs["peak_gas_pressure"] == f1.attrs["peak_gas_pressure"]
        assert f.attrs["density_at_lighting"] == f1.attrs["density_at_lighting"]


def test_blast_slice_reports_peak_pressures(tmp_path):
    out = tmp_path / "bs"
    res = run_cli(["run", "blast_slice", "--out", str(out), "--quiet",
                   "--set", "parts.2.shape.radius=0.009", "--set", "time.t_end=1.5e-6",
                   "--set", "parts.0.shape.z=[0.0, 0.004]", "--set", "parts.1.shape.z=[0.0, 0.004]",
                   "--set", "parts.2.shape.z=[0.0, 0.004]", "--set", "probes.0.position=[0.00405, 0.0, 0.002]",
                   "--set", "probes.1.position=[0.0075, 0.0, 0.002]",
                   "--set", "probes.2.position=[0.0085, 0.0, 0.002]"], ranks=2)
    assert res.returncode == 0, res.stdout + res.stderr
    line = [ln for ln in res.stdout.splitlines() if "peak gas pressure" in ln]
    assert line
    peak = float(line[0].split("peak gas pressure")[1].split()[0])
    assert 3.0 < peak < 20.0                       # GPa: between p(1, e0)/2 and above p_CJ
    wall = [ln for ln in res.stdout.splitlines() if "probe wall" in ln]
    assert wall and float(wall[0].split("peak radial stress")[1].split()[0]) < -10.0
    assert "peak gas pressure" in (out / "run.log").read_text()
    searched = [ln for ln in res.stdout.splitlines() if "gas families searched" in ln]
    assert searched and 0 < int(searched[0].split("searched")[1].split()[0]) <= 101   # 100 steps


#: a charge slab between two copper plates, the gas pushed along them (+z, 1 km/s) and
#: detonated from z = 0: within 40 steps the gas at the top of a slab has moved past
#: the static halo of its owner, next to copper that the owner does not hold as a ghost
GAS_REACH = """
[scene]
name = "gas_reach"

[time]
dt = 1.5e-8
t_end = 1.5e-6

[materials.explosive]
model = "jwl"
damping = 0.0
interacts_with = ["copper"]

[materials.copper]
model = "j2"

[[parts]]
name = "charge"
material = "explosive"
dx = 5.0e-4
shape = { kind = "box", lo = [-0.0015, -0.0015, 0.0], hi = [0.0015, 0.0015, 0.008] }

[[parts]]
name = "left"
material = "copper"
dx = 5.0e-4
shape = { kind = "box", lo = [-0.0025, -0.0015, 0.0], hi = [-0.0015, 0.0015, 0.008] }

[[parts]]
name = "right"
material = "copper"
dx = 5.0e-4
shape = { kind = "box", lo = [0.0015, -0.0015, 0.0], hi = [0.0025, 0.0015, 0.008] }

[[initial]]
kind = "uniform_velocity"
region = { lo = [-0.0015, -0.0015, 0.0], hi = [0.0015, 0.0015, 0.008] }
velocity = [0.0, 0.0, 1000.0]

[output]
every = 20
fields = ["u", "v", "pressure"]
"""


def beyond_static_halo(scene, ranks, y, is_gas, is_solid):
    """Pairs (gas point, copper point) closer than the gas horizon in the current
    positions y where the copper point lies outside the gas owner's static halo
    (slabs.reach): the pairs a rank can only see if it holds that copper anyway."""
    from scipy.spatial import cKDTree

    from mpipd.input.geometry import LayerTable
    from mpipd.parallel.decomp import decompose, halo_width
    table = LayerTable.from_parts(scene.parts, scene.material_ids)
    slabs = decompose(table, ranks, halo_width(scene))
    horizon = max(q.horizon for q in scene.parts if q.material == "explosive")
    gas, solid = np.flatnonzero(is_gas), np.flatnonzero(is_solid)
    pairs = cKDTree(y[gas]).query_ball_tree(cKDTree(y[solid]), horizon)
    found = 0
    for r in range(ranks):
        lo, hi = slabs.reach(r)
        near = np.zeros(len(y), bool)
        for L in range(lo, hi):
            near[table.start[L]:table.start[L] + table.count[L]] = True
        g0, g1 = slabs.gid_range(r)
        for a, js in enumerate(pairs):
            if g0 <= gas[a] < g1:
                found += int(np.sum(~near[solid[js]]))
    return found


def test_gas_past_its_slab_sees_the_same_solids_on_1_2_3_ranks(tmp_path):
    """Gas moves far from the slab of the rank that owns it; the solids it acts on
    (``interacts_with``) must be in its family wherever it goes, on any number of
    ranks, or the answer depends on the decomposition.  The 1-rank run's gas ends
    within a horizon of copper outside its 2- and 3-rank owners' static halos (so
    the case tests that path); u, v and pressure of every frame are then bit-identical
    on 1, 2 and 3 ranks.  (Before the interacting solids were replicated, the 2-rank
    run left the 1-rank one at step 39: a gas point at the top of rank 0's slab lost
    the copper past the halo from its M and L.)"""
    path = tmp_path / "gas_reach.toml"
    path.write_text(GAS_REACH)
    out = {}
    for n in (1, 2, 3):
        res = run_cli(["run", str(path), "--out", str(tmp_path / f"n{n}"), "--quiet"],
                      ranks=n, timeout=300)
        assert res.returncode == 0, res.stdout + res.stderr
        out[n] = tmp_path / f"n{n}" / "run.h5"
    scene, _ = sc.load(str(path))
    with h5py.File(out[1], "r") as f1:
        ref = {k: f1[k][...] for k in ("fields/u", "fields/v", "fields/pressure")}
        x, mat = f1["geometry/x"][...], f1["geometry/material"][...]
    names = list(scene.materials)
    y = x + ref["fields/u"][-1]
    for n in (2, 3):
        assert beyond_static_halo(scene, n, y, mat == names.index("explosive"),
                                  mat == names.index("copper")) > 0
        with h5py.File(out[n], "r") as f:
            for k, a in ref.items():
                assert np.array_equal(f[k][...], a), f"{k} differs between 1 and {n} ranks"
    assert ref["fields/pressure"][-1].max() > 1e9                # the charge is burning


def _brute_pairs(y, rows, el, h, skin, gid, n):
    """Every (i in rows, j in el), i != j, closer than max(h_i, h_j) + skin, each row
    in gid order: the definition, by a double loop."""
    fam = {}
    for i in rows:
        js = [j for j in el if j != i
              and np.linalg.norm(y[j] - y[i]) < max(h[i], h[j]) + skin]
        fam[int(i)] = sorted(js, key=lambda j: gid[j])
    return fam


@pytest.mark.parametrize("spread", [1.0, 40.0, 400.0])   # dense, dense, sparse cells
def test_cell_list_finds_exactly_the_pairs_within_reach(spread):
    """Random points (gas with a horizon, solids with none), some rows; clustered, and
    spread over many empty cells: the cell list gives the pairs of the definition,
    each row sorted by gid, and so does the k-d tree it falls back to."""
    from mpipd.kernels.search import cell_counts, cell_pairs
    rng = np.random.default_rng(7)
    n_local, n = 900, 600
    y = rng.uniform(0.0, 0.01, (n_local, 3))
    y[::7] *= spread                                   # some far away
    gid = rng.permutation(n_local).astype(np.int64)
    h = np.where(rng.random(n_local) < 0.5, 1.5e-3, 0.0)
    skin = 0.3e-3
    el = np.flatnonzero(rng.random(n_local) < 0.8)
    rows = el[el < n]
    cell = h.max() + skin
    lo, dims = cell_counts(y[el], cell)
    counts, nbr = cell_pairs(y, rows, el, h, skin, cell, lo, dims, gid, n)
    want = _brute_pairs(y, rows, el, h, skin, gid, n)
    off = np.concatenate(([0], np.cumsum(counts)))
    assert counts.sum() == sum(len(v) for v in want.values()) > 0
    for i in range(n):
        assert list(nbr[off[i]:off[i + 1]]) == want.get(i, [])
    # the gas's families: a solid row among the gas only (a solid-solid pair carries
    # no force), by the split cell lists and by the k-d tree
    from types import SimpleNamespace

    from mpipd.model.gas import Gas
    is_gas = (h > 0).astype(np.uint8)
    gas_all = np.flatnonzero(is_gas)
    gas = SimpleNamespace(rows=rows, el_ext=el, reach=h.max(), skin=skin, h_ext=h,
                          gid_ext=gid, isgas_ext=is_gas, gas_all=gas_all[np.isin(gas_all, el)],
                          gas_idx=rows[is_gas[rows] > 0], solids_owned=rows[is_gas[rows] == 0],
                          offsets=np.zeros(n + 1, np.int64))
    want = {i: [j for j in js if is_gas[i] or is_gas[j]] for i, js in want.items()}
    Gas._pairs(gas, y, n)
    c2, n2 = Gas._tree_pairs(gas, y, n)
    assert np.array_equal(np.diff(gas.offsets), c2) and np.array_equal(gas.nbr, n2)
    off = gas.offsets
    assert off[-1] == sum(len(v) for v in want.values()) > 0
    for i in range(n):
        assert list(n2[off[i]:off[i + 1]]) == want.get(i, [])


@pytest.mark.parametrize("spread", [1.0, 40.0, 1.0e9])
def test_near_cells_keeps_every_candidate_within_a_cell(spread):
    """near_cells keeps, in order, every candidate within one cell of some ``around``
    point (brute force here) and none beyond the farthest corner of the next cell
    (2 sqrt 3 cells); a box too large for the cell keys drops no candidate."""
    from mpipd.kernels.search import near_cells
    rng = np.random.default_rng(11)
    y = rng.uniform(-0.01, 0.01, (700, 3))
    y[::13] *= spread
    around = np.flatnonzero(rng.random(700) < 0.15)
    cand = np.flatnonzero(rng.random(700) < 0.7)
    cell = 1.5e-3
    got = near_cells(y, cand, around, cell)
    d = np.linalg.norm(y[cand][:, None] - y[around][None], axis=-1).min(axis=1)
    assert set(cand[d < cell]) <= set(got) and np.all(np.diff(got) > 0)
    if spread < 1e6:
        assert 0 < len(got) < len(cand)
        dg = np.linalg.norm(y[got][:, None] - y[around][None], axis=-1).min(axis=1)
        assert dg.max() < 2.0 * np.sqrt(3.0) * cell
    else:
        assert np.array_equal(got, cand)
    assert len(near_cells(y, cand, around[:0], cell)) == 0


# ------------------------------------------------------------------ where the gas acts
def _lattice_update(gas_mask, a=2.0e5, h=4.0e-4):
    """One gas_update on a 7 x 7 x 7 cubic lattice (spacing h, gas horizon 3h) under
    the affine compression v = -a x, every listed gas point lit at its loaded density:
    returns (gd, e, n_bad, gas_idx, centre index)."""
    from mpipd.kernels.ul import GasParams, gas_update
    g = (np.arange(7) - 3) * h
    x = np.stack(np.meshgrid(g, g, g, indexing="ij"), -1).reshape(-1, 3)
    n = len(x)
    is_gas = gas_mask(x).astype(np.uint8)
    gas_idx = np.flatnonzero(is_gas).astype(np.int64)
    delta = np.where(is_gas > 0, 3.0 * h, 0.0)
    d = np.linalg.norm(x[:, None] - x[None], axis=-1)
    near = (d < 3.3 * h) & ~np.eye(n, dtype=bool)
    offsets = np.concatenate(([0], np.cumsum(near.sum(1)))).astype(np.int64)
    nbr = np.nonzero(near)[1].astype(np.int32)
    V = np.full(n, h ** 3)
    gd = np.zeros((n, 8))
    gd[:, 6] = V
    e = np.full(len(gas_idx), 7.38e9)
    dt = 2.0e-8
    n_bad, _ = gas_update(gas_idx, x.copy(), -a * x, V, V.copy(), V.copy(), gd, delta, offsets,
                          nbr, dt, 1.0, np.zeros(len(gas_idx)), V[gas_idx].copy(), e, is_gas,
                          np.zeros(len(gas_idx)), np.zeros(len(gas_idx)),
                          GasParams(0.0, 568e9, 21.6e9, 5.81, 1.77, 0.282, 1.0))
    centre = int(np.flatnonzero(np.all(x == 0.0, axis=1))[0])
    return gd, e, n_bad, gas_idx, centre, x, dt


@pytest.mark.parametrize("where, acts", [
    ("block", True),            # all gas: the interior point measures tr L = -3a
    ("wall", True),             # gas for z <= 0, solid above: the wall's motion counts
    ("slab", True),             # three gas layers among solid: still a volume of gas
    ("lone", False),            # one gas point among solid points
    ("sheet", False),           # one gas layer (z = 0) among solid: coplanar gas
    ("line", False),            # a row of gas along x among solid
])
def test_a_gas_point_acts_only_among_gas(where, acts):
    """A gas point carries pressure where its gas neighbours span a volume: the affine
    field gives tr L = -3a at a full family, so V_R = exp(-3a dt) and p = JWL(V_R, e)
    with e from the trapezoidal work, and the force state -p M^-1 (M over the whole
    family, computed here directly).  A point whose gas neighbours lie on a plane or a
    line, or that has none, carries no force and keeps its volume and energy."""
    masks = {"block": lambda x: np.ones(len(x), bool),
             "wall": lambda x: x[:, 2] <= 0.0,
             "slab": lambda x: np.abs(x[:, 2]) < 1.5 * 4.0e-4,
             "lone": lambda x: np.all(x == 0.0, axis=1),
             "sheet": lambda x: x[:, 2] == 0.0,
             "line": lambda x: (x[:, 1] == 0.0) & (x[:, 2] == 0.0)}
    a, h = 2.0e5, 4.0e-4
    gd, e, n_bad, gas_idx, c, x, dt = _lattice_update(masks[where], a, h)
    k = int(np.flatnonzero(gas_idx == c)[0])
    V0 = h ** 3
    if not acts:
        assert np.all(gd[c, :6] == 0.0) and gd[c, 6] == V0
        assert e[k] == 7.38e9
        assert n_bad >= 1
        return
    VR = math.exp(-3.0 * a * dt)
    np.testing.assert_allclose(gd[c, 6] / V0, VR, rtol=1e-9)
    A, B, R1, R2, w = 568e9, 21.6e9, 5.81, 1.77, 0.282
    f = A * (1 - w / (R1 * VR)) * math.exp(-R1 * VR) + B * (1 - w / (R2 * VR)) * math.exp(-R2 * VR)
    b = V0 * (-3.0 * a) * dt                    # V_w tr L dt
    e_want = (7.38e9 * V0 - 0.5 * f * b) / (V0 + 0.5 * w * b / VR)
    p = f + w * e_want / VR
    np.testing.assert_allclose(e[k], e_want, rtol=1e-12)
    np.testing.assert_allclose(gd[c, 7], p, rtol=1e-12)
    Y = x - x[c]
    ly = np.linalg.norm(Y, axis=1)
    wgt = np.where(ly < 3.0 * h, (3.0 * h - ly) ** 2, 0.0) * h ** 3
    wgt[c] = 0.0
    Mi = np.linalg.inv((Y * wgt[:, None]).T @ Y)
    want = -p * Mi[[0, 1, 2, 1, 0, 0], [0, 1, 2, 2, 2, 1]]
    np.testing.assert_allclose(gd[c, :6], want, rtol=1e-9, atol=1e-9 * np.abs(want).max())


@pytest.mark.parametrize("s, acts", [(0.45, True), (-0.45, True), (0.55, False),
                                     (-0.55, False), (4.7, False)])
def test_a_family_collapsing_or_bursting_in_one_step_carries_no_force(s, acts):
    """The affine field v = -a x gives tr L dt = -3 a dt = -s at the block's centre.
    Within MAX_VOLUME_STRAIN = 0.5 the point acts (V_R = exp(-s), e from the
    trapezoid's closed form); beyond it, compressed or expanded, it carries no force
    and keeps its volume and energy.  At s = 4.7 (the four gas points that met on the
    charge's axis in blast_paper:paper_coupling, issue 15) the closed form's
    denominator V0 + w b / (2 V_R) is negative: the update would give e < 0."""
    from mpipd.kernels.ul import MAX_VOLUME_STRAIN
    assert MAX_VOLUME_STRAIN == 0.5
    h, dt = 4.0e-4, 2.0e-8
    a = s / (3.0 * dt)
    gd, e, n_bad, gas_idx, c, x, _ = _lattice_update(lambda x: np.ones(len(x), bool), a, h)
    k = int(np.flatnonzero(gas_idx == c)[0])
    V0, w = h ** 3, 0.282
    VR, b = math.exp(-s), -s * V0
    if acts:
        np.testing.assert_allclose(gd[c, 6] / V0, VR, rtol=1e-9)
        assert e[k] != 7.38e9 and np.any(gd[c, :6] != 0.0)
        assert (e[k] > 7.38e9) == (s > 0)          # compression heats, expansion cools
        return
    assert np.all(gd[c, :6] == 0.0) and gd[c, 6] == V0 and e[k] == 7.38e9
    assert n_bad >= 1
    if s > 1.5:
        assert V0 + 0.5 * w * b / VR < 0.0


# ------------------------------------------------------------------ gas-solid contact
def _pair_gather(ly_now, xi, frac=0.9, kc=59.0e9, h_gas=4.0e-4, h_solid=3.0e-4, gas_j=False):
    """gas_gather on one pair, gas point 0 and point 1 (a solid, or gas if gas_j), no
    pressure: point 1 sits at reference distance xi and current distance ly_now
    along a fixed oblique unit vector.  Returns (forces (N) on 0 and 1, unit vector,
    y, x, V, offsets, nbr, is_gas)."""
    from mpipd.kernels.ul import gas_gather
    e = np.array([0.48, -0.6, 0.64])
    e /= np.linalg.norm(e)
    x = np.array([[0.0, 0.0, 0.0], xi * e])
    y = np.array([[1e-4, 2e-4, -1e-4], [1e-4, 2e-4, -1e-4] + ly_now * e])
    V = np.array([h_gas ** 3, (h_gas if gas_j else h_solid) ** 3])
    is_gas = np.array([1, 1 if gas_j else 0], np.uint8)
    offsets = np.array([0, 1, 2], np.int64)
    nbr = np.array([1, 0], np.int32)
    gd = np.zeros((2, 8))
    gd[:, 6] = V
    f = np.zeros((2, 3))
    gas_gather(np.array([0, 1], np.int64), y, V, V.copy(), np.ones(2), gd,
               np.array([1.5e-3, 1.5e-3 if gas_j else 0.0]), offsets, nbr, is_gas, f, x,
               frac, kc)
    return f * V[:, None], e, (y, x, V, offsets, nbr, is_gas)


@pytest.mark.parametrize("ly, xi, dc", [
    (2.0e-4, 6.0e-4, 0.9 * 3.5e-4),     # a pair that was apart: d_c = 0.9 l
    (2.0e-4, 2.5e-4, 2.5e-4),           # loaded closer than 0.9 l: d_c = |xi| (no force at rest)
    (2.5e-4, 2.5e-4, 2.5e-4),           # at its reference distance: none
    (3.3e-4, 6.0e-4, 0.9 * 3.5e-4),     # beyond d_c: none
])
def test_gas_solid_contact_force_and_potential(ly, xi, dc):
    """A gas point (spacing 0.4 mm) and a solid point (0.3 mm): l = 0.35 mm, and the pair
    repels with F = k l (d_c - |Y|) along Y, equal and opposite, where |Y| < d_c =
    min(0.9 l, |xi|); its potential k l (d_c - |Y|)^2 / 2 is gas_contact_energy, whose
    gradient (central differences) is the force.  A gas-gas pair has no contact."""
    from mpipd.kernels.ul import gas_contact_energy
    kc, ell = 59.0e9, 3.5e-4
    F, e, (y, x, V, off, nbr, g) = _pair_gather(ly, xi)
    mag = kc * ell * max(dc - ly, 0.0)
    np.testing.assert_allclose(F[0], -mag * e, rtol=1e-9, atol=1e-9 * kc * ell * 1e-4)
    assert np.array_equal(F[1], -F[0]) or np.allclose(F[1], -F[0], rtol=1e-14)
    E = gas_contact_energy(np.array([0], np.int64), y, x, V, off, nbr, g, 0.9, kc)
    np.testing.assert_allclose(E, 0.5 * kc * ell * max(dc - ly, 0.0) ** 2, rtol=1e-9, atol=1e-30)
    h = 1e-9
    for a in range(3):
        yp, ym = y.copy(), y.copy()
        yp[0, a] += h
        ym[0, a] -= h
        dE = (gas_contact_energy(np.array([0], np.int64), yp, x, V, off, nbr, g, 0.9, kc)
              - gas_contact_energy(np.array([0], np.int64), ym, x, V, off, nbr, g, 0.9, kc))
        np.testing.assert_allclose(-dE / (2 * h), F[0, a], rtol=1e-5, atol=kc * ell * h)  # kink at d_c
    Fg = _pair_gather(ly, xi, gas_j=True)[0]
    assert np.all(Fg == 0.0)
    assert np.all(_pair_gather(ly, xi, frac=0.0)[0] == 0.0)     # off: no force


#: an unlit charge block thrown (+x, 1 km/s) at a copper block 1 mm away: without the
#: contact its points fly into the copper (nothing in Eqs. 45-48 stops them)
GAS_IMPACT = """
[scene]
name = "gas_impact"

[time]
dt = 1.5e-8
t_end = 1.8e-6

[materials.explosive]
model = "jwl"
damping = 0.0
interacts_with = ["copper"]

[materials.copper]
model = "j2"

[[parts]]
name = "charge"
material = "explosive"
dx = 5.0e-4
shape = { kind = "box", lo = [-0.002, -0.0015, 0.0], hi = [0.0, 0.0015, 0.006] }
initiation = { never = true }          # unlit all run (mpipd.model.gas.check_charges)

[[parts]]
name = "plate"
material = "copper"
dx = 5.0e-4
shape = { kind = "box", lo = [0.0005, -0.0015, 0.0], hi = [0.0025, 0.0015, 0.006] }

[[initial]]
kind = "uniform_velocity"
region = { lo = [-0.002, -0.0015, 0.0], hi = [0.0, 0.0015, 0.006] }
velocity = [1000.0, 0.0, 0.0]

[output]
every = 10
fields = ["u", "v"]
"""
CONTACT = "materials.explosive.contact={ distance = 0.9, stiffness = 1.0 }"


def test_gas_contact_keeps_a_thrown_charge_out_of_a_copper_plate(tmp_path):
    """Without the contact the unlit gas passes into the plate (its points end beyond
    the plate's first layer); with it no gas point passes the plate's first layer at
    any frame, its first layer is thrown back, the ledger closes with the contact's potential
    booked (gas_contact > 0 during the impact; the closure error, 1.8e-4 at dt = 15 ns,
    falls as dt^2: 6.2e-5 at dt / 2 and 1.2e-5 at dt / 4), and u and v are bit-identical on 1, 2
    and 3 ranks and after a restart on 3 ranks of a run stopped on 2."""
    path = tmp_path / "impact.toml"
    path.write_text(GAS_IMPACT)
    out = {}
    for n, extra in ((1, ["--set", CONTACT]), (2, ["--set", CONTACT]), (3, ["--set", CONTACT]),
                     ("off", []), ("half", ["--set", CONTACT, "--set", "time.dt=7.5e-9"])):
        res = run_cli(["run", str(path), "--out", str(tmp_path / f"n{n}"), "--quiet", *extra],
                      ranks=n if isinstance(n, int) else 1, timeout=300)
        assert res.returncode == 0, res.stdout + res.stderr
        out[n] = tmp_path / f"n{n}" / "run.h5"

    def gas_and_plate(f):
        mat = f["geometry/material"][...]
        y = f["geometry/x"][...][None] + f["fields/u"][...]
        front = f["geometry/x"][...][mat == 0, 0] > -5.0e-4     # the charge's first layer
        return y[:, mat == 0, 0], y[:, mat == 1, 0], f["fields/v"][...][:, mat == 0, 0][:, front]

    with h5py.File(out["off"], "r") as f:
        gx, px, _ = gas_and_plate(f)
        assert gx[-1].max() > px[-1].min() + 2.0e-4        # passed into the plate
    with h5py.File(out[1], "r") as f:
        gx, px, gv = gas_and_plate(f)
        assert np.all(gx.max(axis=1) < px.min(axis=1))     # never past its first layer
        assert np.all(gv[-1] < 0.0)                         # its first layer thrown back
        en = f["energy"]
        assert en["gas_contact"][...].max() > 1e-3 * en["initial"][0]
        err = np.abs(en["balance"][...]).max()
        ref = {k: f[k][...] for k in ("fields/u", "fields/v")}
    with h5py.File(out["half"], "r") as f:     # the closure error is the step's: O(dt^2)
        err_half = np.abs(f["energy/balance"][...]).max()
    assert err < 5e-4 and err_half < err / 2.5, (err, err_half)
    for n in (2, 3):
        with h5py.File(out[n], "r") as f:
            for k, a in ref.items():
                assert np.array_equal(f[k][...], a), f"{k} differs between 1 and {n} ranks"
    d = tmp_path / "r"
    res = run_cli(["run", str(path), "--out", str(d), "--quiet", "--set", CONTACT,
                   "--stop-after", "60"], ranks=2, timeout=300)
    assert res.returncode == 0, res.stdout + res.stderr
    done = restart_matches(d / "checkpoint.h5", out[1], ("fields/u", "fields/v"), ranks=3)
    with h5py.File(done, "r") as f, h5py.File(out[1], "r") as g:    # sums over ranks
        np.testing.assert_allclose(f["energy/gas_contact"][...], g["energy/gas_contact"][...],
                                   rtol=1e-12)


def test_a_gas_contact_distance_above_one_is_refused():
    with pytest.raises(sc.SceneError, match="distance"):
        sc.load("detonation_tube", ["materials.explosive.contact={ distance = 1.5 }"])
    with pytest.raises(sc.SceneError, match="stiff"):
        sc.load("detonation_tube", ["materials.explosive.contact={ stiff = 1.0 }"])


def test_the_skin_changes_how_often_the_gas_is_searched_not_the_answer(team):
    """The Verlet list with the tuned skin (mpipd.model.gas.SkinTuner), with the
    largest skin held, and a search at every step: the same positions and
    velocities bit for bit after the detonation has driven the tube."""
    from mpipd.model.gas import SKIN_MAX
    over = ["parts.2.shape.radius=0.005", "time.t_end=2e-6"]
    out = {}
    for how in ("tuned", "largest", "every step"):
        scene, _ = sc.load("detonation_tube", over)
        sim = Simulation(scene, team)
        g = sim.gas
        if how == "every step":
            g._stale = lambda y: True
        elif how == "largest":
            g.tuner.next = lambda cost: SKIN_MAX
        while sim.step_count < scene.time.n_steps:
            sim.step()
        n = sim.points.n_owned
        out[how] = (sim.u[:n].copy(), sim.v[:n].copy(), g.searches)
    for how in ("largest", "every step"):
        assert np.array_equal(out[how][0], out["tuned"][0])
        assert np.array_equal(out[how][1], out["tuned"][1])
    assert out["every step"][2] > 2 * out["largest"][2]
    assert np.abs(out["tuned"][1]).max() > 100.0   # the gas and tube moved


def test_the_skin_tuner_settles_at_the_cheapest_skin():
    """SkinTuner on a made-up cost per step c(f) = 0.02 / f + f^3 (searches against
    list length; least at f = 0.35): from SKIN it climbs to the minimum and stays
    within a step of it; with the least cost beyond SKIN_MAX it stays at SKIN_MAX."""
    from mpipd.model.gas import SKIN, SKIN_MAX, SKIN_STEP, SkinTuner
    for cost, best in ((lambda f: 0.02 / f + f ** 3, (0.02 / 3) ** 0.25),
                       (lambda f: 1.0 / f, SKIN_MAX)):
        t = SkinTuner()
        assert t.frac == SKIN
        seen = []
        for _ in range(40):
            seen.append(t.next(cost(t.frac)))
        tail = np.array(seen[10:])
        assert np.all(tail >= SKIN) and np.all(tail <= SKIN_MAX)
        assert np.all(tail <= best * SKIN_STEP ** 2 + 1e-12)
        assert np.all(tail >= best / SKIN_STEP ** 2 - 1e-12)
