"""`mpipd check`: every built-in scene passes; sizes per material and per rank without
building the model; bond counts equal the solver's; the critical step per material
and the refusal of `mpipd run` agree; thin slabs and the EOS are reported."""
import re
import time

import numpy as np
import pytest
from conftest import make_scene, run_cli

from mpipd.check import check_report, layer_bonds
from mpipd.input import scene as sc
from mpipd.input.geometry import LayerTable
from mpipd.model.stability import critical_dt
from mpipd.solver import Simulation

BUILTIN = sorted(sc.builtin_scenes())


@pytest.mark.parametrize("name", BUILTIN)
def test_every_builtin_scene_passes_check(name):
    t0 = time.perf_counter()
    res = run_cli(["check", name, "--ranks", "2"], timeout=600)
    took = time.perf_counter() - t0
    assert res.returncode == 0, res.stderr
    out = res.stdout
    for needle in ("per material", "critical dt", "assumed wave speed", "rank 0:", "rank 1:",
                   "MiB", "time step:"):
        assert needle in out, (needle, out)
    assert "TOO LARGE" not in out                   # the built-in scenes run as shipped
    assert took < 120, f"check took {took:.0f} s"


def total_points(text):
    return int(re.search(r"total: (\d+) points", text).group(1))


def test_blast_paper_has_the_papers_size():
    res = run_cli(["check", "blast_paper", "--ranks", "24"], timeout=600)
    assert res.returncode == 0, res.stderr
    n = total_points(res.stdout)
    assert 1.6e6 <= n <= 1.7e6, n                  # the paper: 1,654,208 points
    assert len(re.findall(r"rank \d+:", res.stdout)) == 24


def two_dx_scene():
    """Two granite boxes side by side in x, 1 mm and 0.5 mm (the coarse/fine interface)."""
    g = {"model": "elastic", "density": 2660.0, "bulk_modulus": 21.9e9, "shear_modulus": 25.7e9}
    return make_scene({
        "scene": {"name": "two_dx"}, "time": {"dt": 1e-8, "steps": 1},
        "materials": {"coarse": g, "fine": dict(g)},
        "parts": [{"name": "a", "material": "coarse", "dx": 1e-3,
                   "shape": {"kind": "box", "lo": [0, 0, 0], "hi": [0.008, 0.006, 0.006]}},
                  {"name": "b", "material": "fine", "dx": 5e-4,
                   "shape": {"kind": "box", "lo": [0.008, 0, 0], "hi": [0.012, 0.006, 0.006]}}]})


SCENES = [
    lambda: sc.load("elastic_wave", ["parts.0.dx=0.004"])[0],
    lambda: sc.load("granite_ring", ["parts.0.dx=0.002"])[0],
    lambda: sc.load("detonation_tube", ["parts.2.shape.radius=0.005"])[0],
    two_dx_scene,
]


@pytest.mark.parametrize("make", SCENES, ids=["wave", "ring", "tube", "two_dx"])
def test_bonds_per_layer_equal_the_solvers(team, make):
    """The check counts bonds from the 2-D cross-sections; the solver builds the 3-D
    families.  Per layer (so per rank and per material too) they are equal."""
    scene = make()
    table = LayerTable.from_parts(scene.parts, scene.material_ids)
    counted = layer_bonds(scene, table)
    sim = Simulation(scene, team)
    fam = sim.families
    n = sim.points.n_owned
    per_point = np.diff(fam.offsets)
    layer = np.searchsorted(table.start, sim.points.gid[:n], side="right") - 1
    solver = np.bincount(layer, weights=per_point, minlength=len(table.z)).astype(np.int64)
    np.testing.assert_array_equal(counted, solver)
    assert int(counted.sum()) == sim.n_bonds_global
    text = check_report(scene, 1)
    assert f"total: {sim.n_global} points, {sim.n_bonds_global} bonds" in text


def test_per_material_and_per_rank_lines():
    scene = sc.load("detonation_tube")[0]
    text = check_report(scene, 3)
    table = LayerTable.from_parts(scene.parts, scene.material_ids)
    bonds = layer_bonds(scene, table)
    for k, name in enumerate(scene.materials):
        ks = [i for i, q in enumerate(scene.parts) if q.material == name]
        sel = np.isin(table.part, ks)
        line = [ln for ln in text.splitlines() if ln.strip().startswith(f"'{name}'")][0]
        assert f"{int(table.count[sel].sum())} points, {int(bonds[sel].sum())} bonds" in line
        assert "critical dt" in line and "assumed wave speed" in line
    ranks = re.findall(r"rank \d+: .*?(\d+) owned .*?, (\d+) bonds", text)
    assert len(ranks) == 3
    assert sum(int(o) for o, _ in ranks) == table.n_points
    assert sum(int(b) for _, b in ranks) == int(bonds.sum())
    assert text.count("explosive ") >= 3           # per-rank split by material
    assert "the gas's moving families are not counted" in text


def test_run_refuses_exactly_above_the_step_check_reports(tmp_path):
    scene = sc.load("elastic_wave", ["parts.0.dx=0.004"])[0]
    dt_c = critical_dt(scene)
    base = ["--set", "parts.0.dx=0.004", "--set", "time.t_end=0.0", "--quiet"]
    above = run_cli(["run", "elastic_wave", "--out", str(tmp_path / "a"), *base,
                     "--set", f"time.dt={dt_c * 1.001!r}"])
    assert above.returncode == 2 and "exceeds the stable estimate" in above.stderr
    chk = run_cli(["check", "elastic_wave", "--set", "parts.0.dx=0.004",
                   "--set", f"time.dt={dt_c * 1.001!r}"])
    assert chk.returncode == 2 and "TOO LARGE" in chk.stdout    # check says so, exit 2
    assert f"stable {dt_c:.4e} s" in chk.stdout
    below = run_cli(["run", "elastic_wave", "--out", str(tmp_path / "b"), *base,
                     "--set", f"time.dt={dt_c * 0.999!r}"])
    assert below.returncode == 0, below.stderr


def test_jh2_eos_is_reported():
    text = check_report(sc.load("granite_ring")[0], 1)
    assert "0.00418..0.00582" in text              # the negative-dp/dmu range
    line = [ln for ln in text.splitlines() if "EOS stiffening" in ln][0]
    mu = float(line.split("at mu = ")[1].split(";")[0])
    assert 0.03 < mu < 0.045                        # dt = 0.23 dt_c: waves up to 20 km/s
    assert "at mu = 0.1" in line
    assert "EOS stiffening" not in check_report(sc.load("elastic_wave")[0], 1)


def test_thin_slabs_are_reported():
    res = run_cli(["check", "elastic_wave", "--ranks", "8"])
    assert res.returncode == 0
    assert res.stdout.count("thinner than the halo") == 9      # 8 ranks + the note
    assert "note: 8 slab(s) thinner than the halo" in res.stdout
    res = run_cli(["check", "elastic_wave", "--ranks", "2"])
    assert "thinner than the halo" not in res.stdout


def test_check_of_too_many_ranks_is_a_clear_error():
    res = run_cli(["check", "elastic_wave", "--ranks", "17"])
    assert res.returncode == 2 and "z levels" in res.stderr
