"""mpipd.post validate: the validation record from synthetic report directories
(report.json in the layout of `mpipd.post report`, tiny PNGs) with known values —
one table row per target, values and verdicts in their run's columns, figures
copied and downscaled, the lattice-bias table when a report has one, the notes
verbatim, and a missing input: one line, exit status 2, nothing written."""
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from conftest import ROOT, child_env
from PIL import Image

from mpipd.post import validation
from mpipd.post.__main__ import main
from mpipd.post.crack_orientation import CLASSES
from mpipd.post.targets import TARGETS, verdict

CONSISTENCY = (6794.0, 15511.0)
BIG, SMALL = (1800, 600), (300, 200)        # figure sizes (px): one wider than 900


def inside(t):
    """A value within target t's range (information rows: any number)."""
    if t.kind == "consistency":
        return 9000.0
    if t.lo is None and t.hi is None:
        return 4100.0
    return t.lo if t.hi is None else t.hi if t.lo is None else 0.5 * (t.lo + t.hi)


def outside(t):
    if t.kind == "consistency":
        return 20000.0
    if t.lo is None and t.hi is None:
        return 3900.0
    if t.unit == "yes/no":
        return 1.0 - t.lo
    return (t.hi + 1.0) if t.hi is not None else t.lo - 1.0


def report_json(case, values, lattice_bias=None, figures=("fig09_fracture_faces",
                                                          "fig12_crack_density")):
    """A report.json like `mpipd.post report` writes (only the blocks the record reads,
    in their layout): ``values`` key -> number, or a string = the not-available reason."""
    rows = []
    for t in TARGETS:
        v = values[t.key]
        judged = {"not_available": v} if isinstance(v, str) else v
        rows.append({"key": t.key, "label": t.label, "unit": t.unit, "kind": t.kind,
                     "value": None if isinstance(v, str) else float(v),
                     "basis": "3 probes" if t.key == "wave_speed" else "",
                     "paper": t.paper, "experiment": t.experiment, "band": t.band,
                     "verdict": verdict(t.key, judged, CONSISTENCY)})
    doc = {"run": {"run_file": f"/somewhere/runs/{case}/run.h5", "label": f"blast_demo ({case})",
                   "n_points": 12345, "run_ranks": 3, "dt_s": 2e-08, "steps": 600,
                   "git_commit": "0123456789abcdef0123456789abcdef01234567",
                   "mpipd_version": "0.1.0", "fields": ["damage"], "bonds_broken": 77,
                   "run_id": f"id-{case}", "n_bonds": 999, "save_every": 100},
           "errors": [], "figures": {f: f + ".png" for f in figures},
           "figures_not_made": {"fig18_ppv": "the run has no peak_speed field"},
           "model": {"scene": "blast_demo", "dx_m": 0.001, "overrides": [], "notes": [],
                     **({"gas_acts_on": ["copper", "granite"]} if case == "alpha" else {})},
           "frames": 7, "t_end_us": 12.0,
           "explosive_reference": {"consistency_MPa": list(CONSISTENCY)}, "targets": rows}
    if lattice_bias is not None:
        doc["lattice_bias"] = lattice_bias
    if case == "alpha":         # its wave speed against the arrival threshold
        doc["wave_speed"] = {"probes": ["A", "B", "C"], "threshold_study": [
            {"fraction": 0.02, "speed_m_s": 5933.4}, {"fraction": 0.1, "speed_m_s": 5616.2},
            {"fraction": 0.5, "error": "first-arrival times do not increase"}]}
    if case == "alpha":         # a run stopped at step 200 on 2 ranks, restarted on 3
        doc["run"]["segments"] = [
            {"from_step": 0, "to_step": 200, "ranks": 2, "wall_s": 60.0,
             "bond_steps_per_s": 999 * 200 / 60.0, "git_commit": "0123",
             "bond_states_evaluated": 0.5},
            {"from_step": 200, "to_step": 600, "ranks": 3, "wall_s": 180.0,
             "bond_steps_per_s": 999 * 400 / 180.0, "git_commit": "0123",
             "bond_states_evaluated": 0.2}]
    return doc


def write_report(d: Path, doc, sizes=(BIG, SMALL)):
    d.mkdir(parents=True)
    (d / "report.json").write_text(json.dumps(doc, indent=1))
    for (name, f), size in zip(doc["figures"].items(), sizes):
        Image.new("RGBA", size, (200, 30, 30, 255)).save(d / f)
    return d


BIAS = {"detonation_face": {"ring_mm": [10.0, 25.0], "n_failed": 321, "a4": 0.41,
                            "a8": 0.12, "noise": 0.05, "major_radial_cracks": 4},
        "mid": {"ring_mm": [10.0, 25.0], "n_failed": 200, "a4": 0.33, "a8": 0.07,
                "noise": 0.04, "major_radial_cracks": 6},
        "ring": "failed points with 10 mm < r < 25 mm"}


@pytest.fixture()
def two_reports(tmp_path):
    good = {t.key: inside(t) for t in TARGETS}
    bad = {t.key: outside(t) for t in TARGETS}
    bad["peak_sigma_rr_G"] = "no probe G"
    a = write_report(tmp_path / "in" / "alpha" / "report",
                     report_json("alpha", good, lattice_bias=BIAS))
    b = write_report(tmp_path / "in" / "beta" / "report", report_json("beta", bad))
    return tmp_path, a, b, good, bad


def table(md: str, heading: str) -> list[list[str]]:
    """The rows (cells) of the first table after ``heading``."""
    part = md.split(heading, 1)[1]
    lines = [ln for ln in part.split("\n## ", 1)[0].splitlines() if ln.startswith("|")]
    return [[c.strip() for c in ln.strip("|").split(" | ")] for ln in lines]


def test_record(two_reports, capsys):
    tmp, a, b, good, bad = two_reports
    out = tmp / "docs" / "validation"
    notes = tmp / "notes.md"
    notes.write_text("### Why zone 3 is high\n\nThe *lattice* bias, see `fig09`.\n")
    rc = main(["validate", "--out", str(out), str(a), str(b), "--notes", str(notes)])
    assert rc == 0, capsys.readouterr().err
    md = (tmp / "docs" / "validation.md").read_text()
    assert md.startswith("# Validation record")
    assert f"`python -m mpipd.post validate --out {out} {a} {b} --notes {notes}`" in md

    rows = table(md, "## Targets")
    head, body = rows[0], rows[2:]
    assert head == ["quantity", "unit", "paper", "experiment", "range used",
                    "alpha", "alpha verdict", "beta", "beta verdict"]
    assert len(body) == len(TARGETS)
    for t, row in zip(TARGETS, body):
        assert row[0] == t.label and row[1] == t.unit and row[2] == t.paper
        assert row[3] == t.experiment
        va, vb = good[t.key], bad[t.key]
        if t.unit == "yes/no":
            assert row[5] == ("yes" if va else "no") and row[7] == ("yes" if vb else "no")
        else:
            assert row[5].split(" (")[0] == validation.number(va)
        want_a = "information" if t.kind == "information" else "**within**"
        want_b = "information" if t.kind == "information" else "**outside**"
        assert row[6] == want_a, t.key
        if t.key == "peak_sigma_rr_G":
            assert row[7] == "—" and row[8] == "not available: no probe G"
        else:
            assert row[8] == want_b, t.key
            if t.unit != "yes/no":
                assert row[7].split(" (")[0] == validation.number(vb)
    assert body[0][5] == f"{good['wave_speed']:.4g} (3 probes)"
    gas = [r for t, r in zip(TARGETS, body) if t.key == "peak_gas_pressure"][0]
    assert gas[7] == "20000" and gas[8] == "**outside**"

    prov = {r[0]: r[1:] for r in table(md, "## Provenance")}
    assert prov["points"] == ["12345", "12345"] and prov["ranks"] == ["3", "3"]
    assert prov["run id"] == ["id-alpha", "id-beta"]
    assert prov["the gas acts on (interacts_with)"] == ["copper, granite", "not in report.json"]
    # alpha: 240 s over two invocations; 999 bonds x 600 steps / 240 s; per rank the
    # time-weighted mean of (999*200/60)/2 and (999*400/180)/3 (computed here)
    per_rank = ((999 * 200 / 60) / 2 * 60 + (999 * 400 / 180) / 3 * 180) / 240
    assert prov["run wall time"] == ["4.0 min (2 invocation(s) on 2/3 rank(s))",
                                     "not recorded"]
    assert prov["throughput"] == [f"{999 * 600 / 240 / 1e6:.2f} M bond-steps/s "
                                  f"({per_rank / 1e6:.2f} M per rank)", "not recorded"]
    # 200 steps at 0.5 and 400 at 0.2 of single-rate's bond states: (100 + 80) / 600
    assert prov["bond states evaluated (of single-rate's)"] == ["0.300", "not recorded"]

    ts = table(md, "## Wave speed against the arrival threshold")
    assert ts[0] == ["run", "probes", "2 %", "10 %", "50 %"]
    assert ts[2:] == [["alpha", "A, B, C", "5933", "5616", "error"]]    # beta has none

    bias = table(md, "## Lattice bias")
    assert bias[0][:3] == ["run", "section", "ring (mm)"]
    assert bias[2] == ["alpha", "detonation_face", "10–25", "321", "0.41", "0.12", "0.05", "4"]
    assert bias[3][:2] == ["alpha", "mid"] and len(bias) == 4       # beta has none
    assert "failed points with 10 mm < r < 25 mm" in md
    assert "No lattice_bias in the report.json of: beta." in md

    assert md.rstrip().endswith(notes.read_text().rstrip())
    assert "## Diagnoses\n\n### Why zone 3 is high\n" in md

    for case, src in (("alpha", a), ("beta", b)):
        d = out / case
        assert (d / "report.json").read_bytes() == (src / "report.json").read_bytes()
        big = Image.open(d / "fig09_fracture_faces.png")
        small = Image.open(d / "fig12_crack_density.png")
        assert big.size == (900, 300) and small.size == SMALL
        assert f"](validation/{case}/fig09_fracture_faces.png)" in md
        assert not (d / "fig18_ppv.png").exists()
    assert "not made: the run has no peak_speed field" in md


def test_summary_table_comes_first_with_the_base_row(two_reports, capsys):
    """The record opens with one table, quantity | experiment | paper | base | verdict,
    a row per judged target (information rows left out) of the row --base names; a
    --base that names no row is refused before anything is written."""
    tmp, a, b, good, bad = two_reports
    out = tmp / "docs" / "validation"
    assert main(["validate", "--out", str(out), str(a), str(b), "--base", "beta"]) == 0
    md = (tmp / "docs" / "validation.md").read_text()
    assert md.index("## Summary") < md.index("## Provenance") < md.index("## Targets")
    rows = table(md, "## Summary")
    assert rows[0] == ["quantity", "experiment", "paper", "beta", "verdict"]
    judged_t = [t for t in TARGETS if t.kind != "information"]
    assert len(rows) - 2 == len(judged_t)
    for t, row in zip(judged_t, rows[2:]):
        assert row[0].startswith(t.label) and row[1] == t.experiment and row[2] == t.paper
        if t.key == "peak_sigma_rr_G":
            assert row[3] == "—" and row[4] == "not available: no probe G"
        else:
            assert row[4] == "**outside**", t.key
    n_out = sum(1 for t in judged_t if t.key != "peak_sigma_rr_G")
    assert f"0 within, {n_out} outside, 1 without a verdict" in md
    # the default is the first run, all within
    assert main(["validate", "--out", str(out), str(a), str(b)]) == 0
    rows = table((tmp / "docs" / "validation.md").read_text(), "## Summary")
    assert rows[0][3] == "alpha" and all(r[4] == "**within**" for r in rows[2:])
    before = (tmp / "docs" / "validation.md").read_bytes()
    assert main(["validate", "--out", str(out), str(a), str(b), "--base", "gamma"]) == 2
    assert "--base gamma: no such row" in capsys.readouterr().err
    assert (tmp / "docs" / "validation.md").read_bytes() == before


def test_changed_verdict_is_flagged(tmp_path, capsys):
    """A verdict stored in report.json that targets.verdict no longer gives (the bands
    changed since the report) is shown beside the current one."""
    k = next(i for i, t in enumerate(TARGETS) if i > 0 and t.kind == "range")
    doc = report_json("old", {t.key: inside(t) for t in TARGETS})
    doc["targets"][k]["verdict"] = "outside"
    d = write_report(tmp_path / "old" / "report", doc)
    assert main(["validate", "--out", str(tmp_path / "v" / "validation"), str(d)]) == 0
    md = (tmp_path / "v" / "validation.md").read_text()
    row = table(md, "## Targets")[2 + k]
    assert row[0] == TARGETS[k].label and row[6] == "**within** (report.json: outside)"


def test_report_made_before_the_paper_measures(tmp_path, capsys):
    """A report.json made when the horizon-linked crack count and the last frame's
    crushed zone were judged, without the paper's measures (the Fig. 11 count, the
    crushed zone at 4 µs, the gas outside the tube): the former rows show today's
    'information' beside their stored verdict, the new rows 'not in report.json'."""
    new = ("major_radial_cracks_fig11", "crushed_zone_first_damage", "gas_outside_tube",
           "gas_beyond_tube_ends")
    doc = report_json("old", {t.key: inside(t) for t in TARGETS})
    doc["targets"] = [r for r in doc["targets"] if r["key"] not in new]
    for r in doc["targets"]:
        if r["key"] in ("major_radial_cracks", "crushed_zone"):
            r["value"], r["kind"], r["verdict"] = 6.0 if r["key"] == "major_radial_cracks" \
                else 1.0, "range", "within"
    d = write_report(tmp_path / "old" / "report", doc)
    assert main(["validate", "--out", str(tmp_path / "v" / "validation"), str(d)]) == 0
    md = (tmp_path / "v" / "validation.md").read_text()
    rows = {r[0]: r for r in table(md, "## Targets")[2:]}
    by = {t.key: t for t in TARGETS}
    assert rows[by["major_radial_cracks"].label][5:] == ["6", "information (report.json: within)"]
    assert rows[by["crushed_zone"].label][5:] == ["1", "information (report.json: within)"]
    for key in new:
        assert rows[by[key].label][5:] == ["—", "not in report.json"]


def test_without_lattice_bias_and_notes(two_reports, capsys):
    tmp, a, b, *_ = two_reports
    out = tmp / "v" / "validation"
    assert main(["validate", "--out", str(out), str(b)]) == 0
    md = (tmp / "v" / "validation.md").read_text()
    assert "## Lattice bias" not in md
    assert "## Wave speed against the arrival threshold" not in md
    assert "No notes were given" in md
    assert len(table(md, "## Targets")) == 2 + len(TARGETS)


def test_missing_input_writes_nothing(two_reports, capsys):
    tmp, a, *_ = two_reports
    out = tmp / "docs" / "validation"
    missing = tmp / "runs" / "blast_paper_dx1.2" / "run.h5"
    capsys.readouterr()
    assert main(["validate", "--out", str(out), str(a), str(missing)]) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1
    assert str(missing) in err
    assert f"mpirun -n 2 mpipd run blast_paper:dx1.2 --out {missing.parent}" in err
    assert not (tmp / "docs").exists()
    assert main(["validate", "--out", str(out), str(tmp / "in")]) == 2       # no report.json
    assert "neither report.json nor run.h5" in capsys.readouterr().err
    assert main(["validate", "--out", str(out), str(a), "--notes", str(tmp / "nope.md")]) == 2
    assert not (tmp / "docs").exists()


def test_how_to_make():
    f = validation.how_to_make
    assert f(Path("runs/demo/run.h5")) == "make demo"
    assert f(Path("runs/blast_paper_dx1.2/run.h5")) == \
        "mpirun -n 2 mpipd run blast_paper:dx1.2 --out runs/blast_paper_dx1.2"
    assert f(Path("runs/blast_demo-graded/run.h5")) == \
        "mpirun -n 2 mpipd run blast_demo:graded --out runs/blast_demo-graded"
    assert f(Path("runs/blast_slice/run.h5")) == \
        "mpirun -n 2 mpipd run blast_slice --out runs/blast_slice"
    assert "SCENE[:CASE]" in f(Path("elsewhere/mine/run.h5"))


def test_make_validate_missing_run(tmp_path):
    """`make validate` with a missing run file: the command's one line, exit status 2."""
    env = child_env()
    env["PYTHONPATH"] = str(ROOT)
    missing = tmp_path / "runs" / "blast_paper_dx1.2" / "run.h5"
    p = subprocess.run(["make", "-s", "-o", "install", "validate", f"PY={sys.executable}",
                        f"VALIDATE_RUNS={missing}", f"VALIDATE_OUT={tmp_path}/studies/validation/record"],
                       cwd=ROOT, capture_output=True, text=True, timeout=120, env=env)
    assert p.returncode == 2
    lines = [ln for ln in p.stderr.splitlines() if not ln.startswith("make")]
    assert len(lines) == 1 and str(missing) in lines[0]
    assert "mpipd run blast_paper:dx1.2" in lines[0]
    assert not (tmp_path / "docs").exists()


def test_steps_that_no_invocation_recorded_are_named():
    """An invocation killed before it could write leaves no segment (the 0.8 mm
    blast_paper run: steps 0-1200 ran, were checkpointed, and the process was killed at
    1300): the wall time is a lower bound and names the steps it lacks."""
    segs = [{"from_step": 1200, "to_step": 1940, "ranks": 2, "wall_s": 1600.0,
             "bond_steps_per_s": 1e6 * 740 / 1600.0},
            {"from_step": 1940, "to_step": 3000, "ranks": 2, "wall_s": 2400.0,
             "bond_steps_per_s": 1e6 * 1060 / 2400.0}]
    assert validation.uncovered(segs, 3000) == [(0, 1200)]
    assert validation.uncovered(segs, 3200) == [(0, 1200), (3000, 3200)]
    # a restart from an earlier checkpoint overlaps the last segment: nothing missing
    assert validation.uncovered([{"from_step": 0, "to_step": 500},
                                 {"from_step": 400, "to_step": 900}], 900) == []
    assert validation._wall(segs, 3000) == ("at least 66.7 min (2 invocation(s) on 2 rank(s); "
                                            "steps 0–1200 not recorded)")
    assert validation._throughput(segs, 3000).endswith("over the recorded steps; steps "
                                                       "0–1200 not recorded")


def test_make_sensitivity_sets_each_case_beside_the_base(tmp_path):
    """`make sensitivity` from report.json rows alone: each case's value beside the
    base's with its difference; without a case row, one line and exit status 2."""
    env = child_env()
    env["PYTHONPATH"] = str(ROOT)
    docs = {}
    for case, n_tension in (("base", 400), ("blast_paper_case3", 300)):
        doc = report_json(case, {t.key: inside(t) for t in TARGETS})
        doc["failure_modes"] = {"intact": 1000, "JH2 plastic (D >= 1)": 50,
                                "JH2 tensile (p < -T)": 0, "tension model (Eq. 38)": n_tension}
        doc["energy_ledger"] = {"balance": [0.0, -2e-5], "final_J": {}}
        docs[case] = write_report(tmp_path / case, doc)
    out = tmp_path / "s.md"
    make = ["make", "-s", "-o", "install", "sensitivity", f"PY={sys.executable}",
            f"SENS_BASE={docs['base']}", f"SENS_OUT={out}"]
    p = subprocess.run(make + [f"SENS_ROWS={docs['blast_paper_case3']}"], cwd=ROOT,
                       capture_output=True, text=True, timeout=120, env=env)
    assert p.returncode == 0, p.stderr
    rows = {r[0]: r[1:] for r in ([c.strip() for c in ln.strip().strip("|").split("|")]
                                  for ln in out.read_text().splitlines() if ln.startswith("|"))}
    assert rows["quantity"] == ["table1", "case3"]
    assert rows["failed: tension model"] == ["400", "300 (-25.0 %)"]      # (300 - 400) / 400
    assert "Run rows from each directory's report.json" in out.read_text()
    p = subprocess.run(make + ["SENS_ROWS="], cwd=ROOT, capture_output=True, text=True,
                       timeout=120, env=env)
    lines = [ln for ln in p.stderr.splitlines() if not ln.startswith("make")]
    assert p.returncode == 2 and len(lines) == 1 and "no case row" in lines[0]


def test_named_cases_list_the_rows_that_ran_them(tmp_path, capsys, monkeypatch):
    """The record's "Named cases" section (mpipd.post.case_coverage): each case of the
    rows' scene with the rows whose report.json names it, the time each reached
    against the case's t_end (read here from the scene file), what it set beyond the
    case's own overrides or lacks of them, and whether its scene changed since its
    commit; a case counts only from a row at its own settings, on today's scene, that
    reached t_end."""
    import tomllib

    from mpipd.post import case_coverage
    scenes = ROOT / "mpipd" / "input" / "scenes"
    base = tomllib.loads((scenes / "blast_demo.toml").read_text())
    cases = tomllib.loads((scenes / "cases" / "blast_demo.toml").read_text())
    t_end = base["time"]["t_end"] * 1e6
    old = {**base, "time": {**base["time"], "dt": 0.5 * base["time"]["dt"]}}

    def at(commit, rel):            # the scene files at a commit: "0ld..." had another dt
        if rel == "blast_demo.toml":
            return old if commit.startswith("0ld") else base
        return cases if rel == "cases/blast_demo.toml" else None
    monkeypatch.setattr(case_coverage, "_file_at", at)
    name = 'scene.name="blast_demo-{}"'.format
    rows = {"base": ("blast_demo", ["output.every=100"], t_end, "a" * 40),
            "old": ("blast_demo", [], t_end, "0ld" + "a" * 37),
            "c1": ("blast_demo-case1", [*cases["case1"]["set"], name("case1")], t_end, "b" * 40),
            "c2": ("blast_demo-case2", [cases["case2"]["set"][0], name("case2")], t_end, "c" * 40),
            "c5": ("blast_demo-case5", [*cases["case5"]["set"], name("case5"), "parts.2.dx=1.2e-3"],
                   0.5 * t_end, "d" * 40)}
    dirs = []
    for case, (scene, overrides, reached, commit) in rows.items():
        doc = report_json(case, {t.key: inside(t) for t in TARGETS})
        doc["model"].update(scene=scene, overrides=overrides)
        doc["t_end_us"] = reached
        doc["run"]["git_commit"] = commit
        dirs.append(str(write_report(tmp_path / case / "report", doc)))
    assert main(["validate", "--out", str(tmp_path / "v" / "validation"), *dirs]) == 0
    md = (tmp_path / "v" / "validation.md").read_text()
    got = {r[0]: r[3] for r in table(md, "### blast_demo")[2:]}
    assert set(got) == {"(the scene)", *cases}
    end = f"{t_end:.4g}"
    assert got["(the scene)"] == (f"base ({end} of {end} µs, aaaaaaa)<br>old ({end} of {end} µs, "
                                  "0ldaaaa; blast_demo.toml has changed since)")
    assert got["case1"] == f"c1 ({end} of {end} µs, bbbbbbb)"
    lacks = ", ".join(f"`{o}`" for o in cases["case2"]["set"][1:])
    assert got["case2"] == f"c2 ({end} of {end} µs, ccccccc; lacks {lacks})"
    assert got["case5"] == (f"c5 ({0.5 * t_end:.4g} of {end} µs: **stopped early**, ddddddd; "
                            "also `parts.2.dx=1.2e-3`)")
    assert got["case3"] == "not run in this record"
    left = [c for c in cases if c != "case1"]
    assert (f"blast_demo: 2 of {len(cases) + 1} (the scene and its {len(cases)} cases) have a "
            "row at their own settings, on today's scene, that reached t_end; not: "
            + ", ".join(left) + ".") in md


def test_named_cases_read_the_scene_at_a_commit_with_git():
    """case_coverage reads a scene file at a commit with git (the scene folder of that
    commit, parsed); an unknown commit gives None, so the row is "not checked"."""
    import tomllib

    from mpipd.post import case_coverage
    head = subprocess.run(["git", "-C", str(ROOT), "rev-parse", "HEAD"], capture_output=True,
                          text=True, check=True).stdout.strip()
    for rel in ("blast_demo.toml", "cases/blast_demo.toml"):
        text = subprocess.run(["git", "-C", str(ROOT), "show",
                               f"{head}:mpipd/input/scenes/{rel}"], capture_output=True,
                              text=True, check=True).stdout
        assert case_coverage._file_at(head, rel) == tomllib.loads(text)
    assert case_coverage._file_at("0" * 40, "blast_demo.toml") is None
    assert case_coverage.scene_changed("0" * 40, "blast_demo", "") is None


def test_orientation_table():
    """Shares of the failed crack length in zones 2-3 per class, computed by hand."""
    def zone(k, lengths, dens):
        z = {"zone": k, "circumferential_density_mm_per_mm2": dens}
        z.update({c: {"points": 0, "length_mm": v} for c, v in zip(
            CLASSES, lengths)})
        return z
    orient = {"zones": [zone(1, (0, 0, 0, 90, 0), 0.0), zone(2, (6, 2, 4, 7, 1), 0.01),
                        zone(3, (10, 2, 6, 1, 1), 0.004)],
              "ring_arcs": 2, "ring_arc_length_mm": 12.5,
              "rings": [{"r_mm": 21.44, "length_mm": 6.0}, {"r_mm": 30.1, "length_mm": 6.5}],
              "failed_rings": [{"r_mm": [64.8, 68.8], "peak_fraction": 0.9887}]}
    older = {k: v for k, v in orient.items() if k != "failed_rings"}
    runs = [{"case": "alpha", "doc": {"fracture": {"sections": {"mid": {"orientation": orient}}}}},
            {"case": "old", "doc": {"fracture": {"sections": {"mid": {"orientation": older}}}}},
            {"case": "beta", "doc": {"fracture": {"sections": {"mid": {"zones": []}}}}}]
    L = validation.orientation_table(runs)
    rows = table("\n".join(L), "## Crack orientation")
    # zones 2-3: radial 16, oblique 4, circumferential 10, unresolved 8, isolated 2 of 40
    assert rows[2] == ["alpha", "mid", "0.40", "0.10", "0.25", "0.20", "0.05",
                       "0.000 / 0.010 / 0.004", "2", "12.5", "21.4, 30.1", "64.8–68.8 (0.99)"]
    assert rows[3][-1] == "not measured"
    assert len(rows) == 4
    assert any("made before it existed): beta." in ln for ln in L)


def test_a_shrunk_figure_is_copied_unchanged(tmp_path):
    """A figure already at most MAX_WIDTH px as a 256-colour PNG (a committed row's,
    `make record`) is copied byte for byte; a full-colour one is shrunk and quantized."""
    big = tmp_path / "big.png"
    rng = np.random.default_rng(1)
    Image.fromarray(rng.integers(0, 255, (300, 1800, 3), dtype=np.uint8)).save(big)
    once, twice = tmp_path / "once.png", tmp_path / "twice.png"
    assert validation.shrink_png(big, once) == (validation.MAX_WIDTH, 150)
    with Image.open(once) as im:
        assert im.mode == "P"
    validation.shrink_png(once, twice)
    assert twice.read_bytes() == once.read_bytes()
