"""``python -m mpipd.post validate --out studies/validation/record RUN [RUN ...] [--notes NOTES.md]``:
a validation record that anyone can re-create from run files (issue 15).

Each RUN is a report directory (``report.json`` and the figures of
``python -m mpipd.post report``), a run folder holding ``run.h5``, or a run file;
for a run folder or run file the report is made first, by
:func:`mpipd.post.report.make_report` (all ranks), into ``report/`` beside the
run file.  Rank 0 then writes

* ``<out>.md`` (``--out studies/validation/record`` writes ``studies/validation/record.md``): the
  command that made it; each run's provenance; the named cases of the rows' scenes
  and the rows that ran each (:mod:`mpipd.post.case_coverage`); one table with a row per target of
  :data:`mpipd.post.targets.TARGETS` — the paper's and the experiment's value and,
  per run, its value and verdict; a section per run with its key figures; the
  lattice-bias table of the reports that have one; the ``--notes`` text verbatim
  under "Diagnoses";
* ``<out>/<case>/``: each run's ``report.json`` (copied unchanged: every number of
  the record is read from it) and its key figures, downscaled to at most 900 px wide.

No number of the record is typed in: values come from each report.json's
``targets`` rows (made by :func:`mpipd.post.analysis.targets_table`), and each
verdict is :func:`mpipd.post.targets.verdict` of the stored value with the bounds
:func:`mpipd.post.analysis.target_bounds` takes from the same report.json (a
verdict that differs from the one stored in report.json is shown with both).

Every input is checked before anything is written: a missing run file, or a
directory without report.json or run.h5, gives one line (naming the file and the
command that makes it) and exit status 2.
"""
from __future__ import annotations

import json
import shlex
import shutil
import subprocess
from dataclasses import dataclass
from pathlib import Path

from .analysis import target_bounds
from .case_coverage import coverage_table
from .crack_orientation import CLASSES, RING_FRACTION, rings_text
from .reader import shown_path
from .targets import BY_KEY, TARGETS, verdict

MAX_WIDTH = 900
KEY_FIGURES = (
    ("fig09_fracture_faces", "fracture pattern on the end faces (Fig. 9)"),
    ("fig11_fracture_sections", "fracture pattern on the sections (Fig. 11)"),
    ("fig12_crack_density", "crack density by zone (Fig. 12)"),
    ("fig16a_radial_stress", "radial stress histories (Fig. 16a)"),
    ("fig17_peak_radial_stress", "peak radial stress against distance (Fig. 17)"),
    ("fig18_ppv", "peak particle velocity (Fig. 18)"),
    ("fig20_rock_energy", "energy in the rock (Fig. 20)"),
)
BIAS_COLUMNS = (("ring_mm", "ring (mm)"), ("n_failed", "failed points"), ("a4", "a4"),
                ("a8", "a8"), ("noise", "noise"),
                ("major_radial_cracks", "major radial cracks"))
NOT_RECORDED = "not recorded"
RANKS_HINT = 2          # the ranks of the suggested `mpirun` (this repository's 2-core default)


class InputError(Exception):
    """A missing or unreadable input: one line, exit status 2, nothing written."""


@dataclass
class Input:
    arg: str                    # as given on the command line
    run_file: Path | None       # the run file whose report is made first, or None
    report_dir: Path            # where report.json is (or will be)


# ------------------------------------------------------------------ inputs

def how_to_make(run_file: Path) -> str:
    """The command that writes ``run_file``: a built-in scene (or SCENE:CASE) named by
    its folder (``runs/blast_paper_dx1.2`` -> ``blast_paper:dx1.2``), ``make demo``
    for ``runs/demo``, else the general form."""
    folder = run_file.parent
    if run_file.name == "run.h5" and folder.name == "demo" and folder.parent.name == "runs":
        return "make demo"
    from mpipd.input.scene import builtin_scenes, cases
    name, run = folder.name, f"mpirun -n {RANKS_HINT} mpipd run"
    scenes = builtin_scenes()
    if run_file.name == "run.h5":
        if name in scenes:
            return f"{run} {name} --out {folder}"
        for scene in sorted(scenes, key=len, reverse=True):
            for sep in ("_", "-"):
                if name.startswith(scene + sep) and name[len(scene) + 1:] in cases(scene):
                    return f"{run} {scene}:{name[len(scene) + 1:]} --out {folder}"
    return f"{run} SCENE[:CASE] --out {folder} (it writes {folder}/run.h5)"


def resolve(args) -> list[Input]:
    """Each argument as an :class:`Input`; :class:`InputError` (naming every missing
    input) if one does not exist."""
    inputs, missing = [], []
    for a in args:
        p = Path(a)
        if p.is_dir() and (p / "report.json").is_file():
            inputs.append(Input(a, None, p))
        elif p.is_dir() and (p / "run.h5").is_file():
            inputs.append(Input(a, p / "run.h5", p / "report"))
        elif p.is_file():
            inputs.append(Input(a, p, p.parent / "report"))
        elif p.is_dir():
            missing.append(f"{a} has neither report.json nor run.h5 (make the report with "
                           f"`mpirun -n {RANKS_HINT} python -m mpipd.post report RUN.h5 --out "
                           f"{a}`)")
        else:
            run_file = p if p.suffix == ".h5" else p / "run.h5"
            missing.append(f"{run_file} does not exist; make it with `{how_to_make(run_file)}`")
    if missing:
        raise InputError(("missing input: " if len(missing) == 1 else "missing inputs: ")
                         + "; ".join(missing))
    return inputs


def load_report(d: Path) -> dict:
    try:
        doc = json.loads((d / "report.json").read_text())
    except (OSError, ValueError) as e:
        raise InputError(f"cannot read {d / 'report.json'}: {' '.join(str(e).split())}") from None
    for key in ("run", "targets", "figures"):
        if key not in doc:
            raise InputError(f"{d / 'report.json'} has no {key!r}: not a report of mpipd.post")
    for name, _ in KEY_FIGURES:
        f = doc["figures"].get(name)
        if f and not (d / f).is_file():
            raise InputError(f"{d / f} is missing (report.json lists it); re-make the report")
    return doc


def case_name(doc, taken) -> str:
    """The run's folder (``runs/demo/run.h5`` -> ``demo``), unique among ``taken``."""
    p = Path(doc["run"].get("run_file") or doc["run"].get("label") or "run")
    base = p.parent.name if p.name == "run.h5" else p.stem
    base = "".join(c if c.isalnum() or c in "._-" else "_" for c in base) or "run"
    name, k = base, 2
    while name in taken:
        name, k = f"{base}-{k}", k + 1
    return name


# ------------------------------------------------------------------ verdicts
def judged(doc) -> dict:
    """key -> (value row of report.json, verdict now, verdict stored in report.json)."""
    bounds = target_bounds(doc) if "explosive_reference" in doc else {}
    out = {}
    for row in doc["targets"]:
        key, v, stored = row["key"], row.get("value"), row.get("verdict", "")
        if key not in BY_KEY:
            continue
        # a row without a value keeps its stored verdict: only that holds the reason
        now = stored if v is None else verdict(key, v, bounds.get(key))
        out[key] = (row, now, stored)
    return out


def _cell(text) -> str:
    return " ".join(str(text).split()).replace("|", "\\|")


def number(v) -> str:
    """4 significant digits, without an exponent for values from 1 to 10^7."""
    g = format(v, ".4g")
    return f"{v:.0f}" if "e" in g and 1 <= abs(v) < 1e7 else g


def value_cell(row, now) -> str:
    v = row.get("value")
    if now.startswith("error"):
        return "**error**"
    if v is None:
        return "—"
    shown = ("yes" if v else "no") if row.get("unit") == "yes/no" else number(v)
    return shown + (f" ({row['basis']})" if row.get("basis") else "")


def verdict_cell(now, stored) -> str:
    shown = f"**{now}**" if now in ("within", "outside") else now
    if now != stored:
        shown += f" (report.json: {stored})"
    return _cell(shown)


# ------------------------------------------------------------------ markdown
def provenance(runs) -> list[str]:
    def get(r, key, fmt=None):
        v = r["doc"]["run"].get(key)
        if v is None:
            return "not in report.json"
        return format(v, fmt) if fmt else str(v)

    def model(r, key):
        return r["doc"].get("model", {}).get(key)

    rows = [
        ("label", lambda r: r["doc"]["run"].get("label", "—")),
        ("scene", lambda r: model(r, "scene") or "not in report.json"),
        ("overrides (--set)", lambda r: "<br>".join(f"`{o}`" for o in model(r, "overrides") or [])
         or "none"),
        ("the gas acts on (interacts_with)",
         lambda r: "not in report.json" if model(r, "gas_acts_on") is None
         else ", ".join(model(r, "gas_acts_on")) or "nothing"),
        ("run file", lambda r: f"`{shown_path(get(r, 'run_file'))}`"),
        ("report.json", lambda r: f"`{r['input'].report_dir / 'report.json'}` → "
         f"`{r['md_dir']}/report.json`"),
        ("run id", lambda r: get(r, "run_id")),
        ("git commit (solver, at run time)", lambda r: get(r, "git_commit")),
        ("mpipd version", lambda r: get(r, "mpipd_version")),
        ("ranks", lambda r: get(r, "run_ranks")),
        ("points", lambda r: get(r, "n_points")),
        ("bonds", lambda r: get(r, "n_bonds")),
        ("rock dx (mm)", lambda r: "not in report.json" if model(r, "dx_m") is None
         else format(model(r, "dx_m") * 1e3, ".3g")),
        ("steps", lambda r: get(r, "steps")),
        ("dt (s)", lambda r: get(r, "dt_s", ".4g")),
        ("simulated time (µs)", lambda r: "not in report.json" if r["doc"].get("t_end_us") is None
         else f"{r['doc']['t_end_us']:.4g} ({r['doc'].get('frames', '?')} frames)"),
        ("bonds broken", lambda r: get(r, "bonds_broken")),
        ("run wall time", lambda r: _wall(r["doc"]["run"].get("segments"),
                                          r["doc"]["run"].get("steps"))),
        ("throughput", lambda r: _throughput(r["doc"]["run"].get("segments"),
                                             r["doc"]["run"].get("steps"))),
        ("bond states evaluated (of single-rate's)",
         lambda r: _evaluated(r["doc"]["run"].get("segments"))),
        ("impossible values (errors)", lambda r: str(len(r["doc"].get("errors", [])))),
    ]
    L = ["## Provenance", "",
         "| | " + " | ".join(r["case"] for r in runs) + " |",
         "|---|" + "---|" * len(runs)]
    for name, fn in rows:
        L.append(f"| {name} | " + " | ".join(_cell(fn(r)) for r in runs) + " |")
    L += ["", "Run wall time and throughput: the time loop's wall time of every `mpipd run` "
          "invocation of the run (a restart adds one; attr `segments` of run.h5, with the "
          "ranks and commit of each), summed; throughput = TL bonds x steps / that time.  "
          "Runs made before the run file kept its segments show 'not recorded'.  An "
          "invocation killed before it could write (no clean stop) leaves no segment: "
          "the steps no segment covers are named, and the time is then a lower bound.  "
          "Bond states evaluated: the share of single-rate's bond states a multi-rate run "
          "evaluated (each segment's `bond_states_evaluated`, weighted by its steps; 1 "
          "single-rate); segments written before 2026-12-05 lack it."]
    return L + [""]


def uncovered(segments, steps) -> list[tuple[int, int]]:
    """The step ranges [a, b) of 0..steps that no segment's from_step..to_step covers
    (an invocation killed before it wrote its segment)."""
    out, at = [], 0
    for s in sorted(segments, key=lambda s: s["from_step"]):
        if s["from_step"] > at:
            out.append((at, s["from_step"]))
        at = max(at, s["to_step"])
    if steps is not None and at < steps:
        out.append((at, int(steps)))
    return out


def _gaps_text(segments, steps) -> str:
    gaps = uncovered(segments, steps)
    return ("; steps " + ", ".join(f"{a}–{b}" for a, b in gaps) + " not recorded"
            if gaps else "")


def _wall(segments, steps=None) -> str:
    """Total loop wall time of a run's invocations, with their count and ranks."""
    if not segments:
        return NOT_RECORDED
    wall = sum(s["wall_s"] for s in segments)
    ranks = sorted({s["ranks"] for s in segments})
    gaps = _gaps_text(segments, steps)
    return (f"{'at least ' if gaps else ''}{wall / 60:.1f} min ({len(segments)} invocation(s) on "
            f"{'/'.join(map(str, ranks))} rank(s){gaps})")


def evaluated_share(segments) -> float | None:
    """The share of single-rate's bond states a run evaluated: each segment's
    ``bond_states_evaluated`` weighted by its steps; None if a segment lacks it (runs
    made before the segments kept it)."""
    if not segments or any(s.get("bond_states_evaluated") is None for s in segments):
        return None
    n = [s["to_step"] - s["from_step"] for s in segments]
    return sum(k * s["bond_states_evaluated"] for k, s in zip(n, segments)) / max(sum(n), 1)


def _evaluated(segments) -> str:
    share = evaluated_share(segments)
    return NOT_RECORDED if share is None else f"{share:.3f}"


def _throughput(segments, steps=None) -> str:
    """Bond-steps per second over a run's recorded invocations, and per rank."""
    if not segments or any(s.get("bond_steps_per_s") is None for s in segments):
        return NOT_RECORDED
    wall = sum(s["wall_s"] for s in segments)
    work = sum(s["bond_steps_per_s"] * s["wall_s"] for s in segments)
    per_rank = sum(s["bond_steps_per_s"] / s["ranks"] * s["wall_s"] for s in segments) / wall
    gaps = _gaps_text(segments, steps)
    return (f"{work / wall / 1e6:.2f} M bond-steps/s ({per_rank / 1e6:.2f} M per rank)"
            + (f" over the recorded steps{gaps}" if gaps else ""))


def summary_table(runs, base: str | None) -> list[str]:
    """The record's first table: one row per judged target (kind "range" or
    "consistency") of the base row, ``quantity | experiment | paper | base row | verdict``,
    the values and verdicts read from its report.json as in :func:`targets_table`.
    ``base``: the case name of the base row (default: the first run)."""
    if not runs:
        return []
    r = next((r for r in runs if r["case"] == base), None) if base else runs[0]
    if r is None:
        raise InputError(f"--base {base}: no such row (the rows: "
                         + ", ".join(x["case"] for x in runs) + ")")
    L = ["## Summary", "",
         f"The base row `{r['case']}` against the experiment and the paper, one row per "
         "judged quantity (the full table of every row is under Targets).", "",
         f"| quantity | experiment | paper | {r['case']} | verdict |", "|---|---|---|---|---|"]
    n = {"within": 0, "outside": 0, "other": 0}
    for t in TARGETS:
        if t.kind == "information":
            continue
        got = r["judged"].get(t.key)
        if got is None:
            value, now, shown = "—", "not in report.json", "not in report.json"
        else:
            row, now, stored = got
            value, shown = value_cell(row, now), verdict_cell(now, stored)
        n["within" if now.startswith("within") else
          "outside" if now.startswith("outside") else "other"] += 1
        unit = f" ({t.unit})" if t.unit and t.unit != "—" else ""
        L.append(f"| {_cell(t.label + unit)} | {_cell(t.experiment)} | {_cell(t.paper)} | "
                 f"{value} | {shown} |")
    L += ["", f"{n['within']} within, {n['outside']} outside, {n['other']} without a verdict "
          "(not available or not in report.json).", ""]
    return L


def targets_table(runs) -> list[str]:
    head = "| quantity | unit | paper | experiment | range used | " + " | ".join(
        f"{r['case']} | {r['case']} verdict" for r in runs) + " |"
    L = ["## Targets", "",
         "One row per target of `mpipd/post/targets.py`.  Values are the `targets` rows of "
         "each run's report.json; verdicts are `targets.verdict` of those values (the "
         "consistency row against the bounds in the same report.json).  'information' rows "
         "are shown, not judged.", "",
         head, "|---|---|---|---|---|" + "---|---|" * len(runs)]
    for t in TARGETS:
        cells = []
        bands = []
        for r in runs:
            got = r["judged"].get(t.key)
            if got is None:
                cells += ["—", "not in report.json"]
                continue
            row, now, stored = got
            cells += [value_cell(row, now), verdict_cell(now, stored)]
            bands.append(row.get("band") or t.band)
        if t.kind == "consistency" and len(set(bands)) > 1:
            band = "; ".join(f"{r['case']}: {b}" for r, b in zip(runs, bands))
        else:
            band = bands[0] if bands else t.band
        L.append(f"| {_cell(t.label)} | {_cell(t.unit)} | {_cell(t.paper)} | "
                 f"{_cell(t.experiment)} | {_cell(band)} | " + " | ".join(cells) + " |")
    L.append("")
    for r in runs:
        extra = [row["key"] for row in r["doc"]["targets"] if row["key"] not in BY_KEY]
        if extra:
            L.append(f"{r['case']}: report.json rows not in targets.py (not shown): "
                     + ", ".join(extra) + ".")
    counts = []
    for r in runs:
        n = {"within": 0, "outside": 0, "information": 0, "not available": 0, "error": 0}
        for _, now, _ in r["judged"].values():
            n[next(k for k in n if now.startswith(k))] += 1
        counts.append(f"{r['case']}: " + ", ".join(f"{v} {k}" for k, v in n.items()))
    L += ["Verdicts: " + "; ".join(counts) + ".", ""]
    return L


def _bias_value(v) -> str:
    if isinstance(v, (list, tuple)):
        return "–".join(_bias_value(x) for x in v)
    if isinstance(v, bool) or isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        return format(v, ".3g")
    return _cell(v if v is not None else "—")


def bias_table(runs) -> list[str]:
    have = [r for r in runs if isinstance(r["doc"].get("lattice_bias"), dict)]
    if not have:
        return []
    keys = [k for k, _ in BIAS_COLUMNS]
    for r in have:
        for sec in r["doc"]["lattice_bias"].values():
            if isinstance(sec, dict):
                keys += [k for k in sec if k not in keys]
    names = dict(BIAS_COLUMNS)
    L = ["## Lattice bias", "",
         "From the `lattice_bias` block of each report.json (failed points on a ring of each "
         "section).", "",
         "| run | section | " + " | ".join(names.get(k, k) for k in keys) + " |",
         "|---|---|" + "---|" * len(keys)]
    notes = []
    for r in have:
        for name, sec in r["doc"]["lattice_bias"].items():
            if isinstance(sec, dict):
                L.append(f"| {r['case']} | {_cell(name)} | "
                         + " | ".join(_bias_value(sec.get(k)) for k in keys) + " |")
            else:
                notes.append(f"- {r['case']}, {name}: {_cell(sec)}")
    L.append("")
    if notes:
        L += notes + [""]
    without = [r["case"] for r in runs if r not in have]
    if without:
        L += [f"No lattice_bias in the report.json of: {', '.join(without)}.", ""]
    return L


def orientation_table(runs) -> list[str]:
    """Crack orientation per run and section (report.json ``fracture.sections.*.
    orientation``, :mod:`mpipd.post.crack_orientation`): the share of each class in
    zones 2-3, the circumferential density per zone and the ring arcs."""
    def secs(r):
        fr = r["doc"].get("fracture", {})
        s = fr.get("sections", {}) if isinstance(fr, dict) else {}
        return {n: v for n, v in s.items() if isinstance(v, dict) and "orientation" in v}
    have = [r for r in runs if secs(r)]
    if not have:
        return []
    L = ["## Crack orientation", "",
         "From `fracture.sections.*.orientation` of each report.json "
         "(mpipd/post/crack_orientation.py): the local direction of the failed points "
         "within the horizon, classed radial (< 30° from e_r), oblique or circumferential "
         "(> 60°) where they form a line; junctions, the crushed zone and wide bands are "
         "unresolved.  Shares are of the failed crack length in zones 2 and 3; the ring "
         "arcs are chains of circumferential points longer than two horizons (their count "
         "splits at each radial crack that crosses them).  The failed rings are rings of "
         f"width dx beyond the crushed zone with at least {RING_FRACTION:g} of their points "
         "failed, under half of those radial, bands of any width: radii in mm and, in brackets, "
         "the largest failed fraction.", "",
         "| run | section | " + " | ".join(f"{c} (zones 2–3)" for c in CLASSES)
         + " | circumferential density zones 1 / 2 / 3 (mm/mm²) | ring arcs | "
         "ring-arc length (mm) | ring-arc radii (mm) | failed rings (mm) |",
         "|---|---|" + "---|" * (len(CLASSES) + 5)]
    for r in have:
        for name, sec in secs(r).items():
            o = sec["orientation"]
            outer = o["zones"][1:]
            tot = sum(z[c]["length_mm"] for z in outer for c in CLASSES)
            share = [sum(z[c]["length_mm"] for z in outer) / tot if tot else float("nan")
                     for c in CLASSES]
            dens = " / ".join(f"{z['circumferential_density_mm_per_mm2']:.3f}"
                              for z in o["zones"])
            radii = ", ".join(f"{a['r_mm']:.3g}" for a in o["rings"]) or "—"
            L.append(f"| {r['case']} | {_cell(name)} | "
                     + " | ".join(f"{v:.2f}" for v in share)
                     + f" | {dens} | {o['ring_arcs']} | {o['ring_arc_length_mm']:.4g} | "
                     f"{radii} | {rings_text(sec)} |")
    L.append("")
    without = [r["case"] for r in runs if r not in have]
    if without:
        L += [f"No crack orientation in the report.json of (made before it existed): "
              f"{', '.join(without)}.", ""]
    return L


def threshold_table(runs) -> list[str]:
    """The first-arrival speed at each fraction of the probes' peaks (report.json
    ``wave_speed.threshold_study``): how much of the judged speed is the measure."""
    have = [r for r in runs if r["doc"].get("wave_speed", {}).get("threshold_study")]
    if not have:
        return []
    fracs = [row["fraction"] for row in have[0]["doc"]["wave_speed"]["threshold_study"]]
    L = ["## Wave speed against the arrival threshold", "",
         "First-arrival speed (m/s) with the threshold at each fraction of every probe's "
         "own peak −σ_rr (report.json `wave_speed.threshold_study`; the judged row uses "
         "10 %).  Pulses that keep their shape give one speed at every fraction.", "",
         "| run | probes | " + " | ".join(f"{f * 100:g} %" for f in fracs) + " |",
         "|---|---|" + "---|" * len(fracs)]
    for r in have:
        ws = r["doc"]["wave_speed"]
        cells = {row["fraction"]: (number(row["speed_m_s"]) if "speed_m_s" in row else
                                   "error" if "error" in row else "n/a")
                 for row in ws["threshold_study"]}
        L.append(f"| {r['case']} | {', '.join(ws.get('probes', []))} | "
                 + " | ".join(cells.get(f, "—") for f in fracs) + " |")
    return L + [""]


def run_section(k, r) -> list[str]:
    doc = r["doc"]
    L = [f"## Run {k}: {doc['run'].get('label', r['case'])}", "",
         f"Report `{r['input'].report_dir}`, copied to `{r['md_dir']}/report.json`.", ""]
    errs = doc.get("errors", [])
    if errs:
        L += ["Impossible values (report.json `errors`):", ""]
        L += [f"- **{e.get('measure', '?')}**: {_cell(e.get('message', ''))}" for e in errs]
        L.append("")
    for name, caption in KEY_FIGURES:
        if name in r["figures"]:
            L += [f"![{caption}]({r['md_dir']}/{r['figures'][name]})", "", f"*{caption}*", ""]
        else:
            why = doc.get("figures_not_made", {}).get(name, "not in report.json")
            L += [f"*{caption}: not made: {_cell(why)}.*", ""]
    return L


def render(runs, command, code_commit, notes, base=None) -> str:
    L = ["# Validation record", "",
         f"Made by `{command}` (mpipd/post at commit {code_commit}); `make validate` "
         "re-creates it from the run files in `VALIDATE_RUNS` (studies/validate.mk).  Every number "
         "below is read from the runs' report.json files, copied beside this file; none is "
         "typed in.", ""]
    L += (summary_table(runs, base) + provenance(runs) + coverage_table(runs) + targets_table(runs)
          + threshold_table(runs)
          + bias_table(runs) + orientation_table(runs))
    for k, r in enumerate(runs, 1):
        L += run_section(k, r)
    L += ["## Diagnoses", ""]
    L += [notes.rstrip("\n"), ""] if notes is not None else ["No notes were given (--notes).", ""]
    return "\n".join(L)


# ------------------------------------------------------------------ files
def shrink_png(src: Path, dst: Path, width: int = MAX_WIDTH) -> tuple[int, int]:
    """``src`` at most ``width`` px wide (aspect kept), on white, as a 256-colour PNG
    (a third of the size of a full-colour one; the figures have few colours).  A
    source that is already such a PNG (a committed row's figure, ``make record``) is
    copied byte for byte: quantizing it again would rewrite the file with no change."""
    from PIL import Image
    with Image.open(src) as im:
        if im.format == "PNG" and im.mode == "P" and im.width <= width:
            shutil.copyfile(src, dst)
            return im.size
        rgba = im.convert("RGBA")
    if rgba.width > width:
        rgba = rgba.resize((width, max(1, round(rgba.height * width / rgba.width))),
                           Image.Resampling.LANCZOS)
    flat = Image.alpha_composite(Image.new("RGBA", rgba.size, "white"), rgba).convert("RGB")
    small = flat.quantize(256, method=Image.Quantize.MEDIANCUT, dither=Image.Dither.NONE)
    small.save(dst, format="PNG", optimize=True)
    return small.size


def code_commit() -> str:
    root = Path(__file__).resolve().parents[2]     # the repository
    try:
        head = subprocess.run(["git", "-C", str(root), "rev-parse", "HEAD"], capture_output=True,
                              text=True, timeout=10, check=True).stdout.strip()
        dirty = subprocess.run(["git", "-C", str(root), "status", "--porcelain", "--",
                                "mpipd/post"], capture_output=True, text=True, timeout=10,
                               check=True).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        return "unknown (not a git checkout)"
    return head[:12] + (" with uncommitted changes in mpipd/post/" if dirty else "")


def make_validation(args, out, comm, notes=None, argv=None, check_only=False,
                    base=None) -> list[str]:
    """The record (module docstring); ``base``: the case name of the row the Summary
    shows (default: the first input)."""
    inputs = resolve(args)
    notes_text = None
    if notes is not None:
        try:
            notes_text = Path(notes).read_text()
        except OSError as e:
            raise InputError(f"cannot read the notes {notes}: {e.strerror or e}") from None
    for inp in inputs:
        if inp.run_file is None:
            load_report(inp.report_dir)
    if check_only:
        return [f"validate: all {len(inputs)} input(s) present"] if comm.Get_rank() == 0 else []
    lines = []
    from .report import make_report
    for inp in inputs:
        if inp.run_file is not None:
            lines += make_report(str(inp.run_file), str(inp.report_dir), comm)
    if comm.Get_rank() != 0:
        return []
    out = Path(out)
    md = out.parent / f"{out.name}.md"
    runs, taken = [], set()
    for inp in inputs:
        doc = load_report(inp.report_dir)
        case = case_name(doc, taken)
        taken.add(case)
        runs.append({"input": inp, "doc": doc, "case": case, "judged": judged(doc),
                     "md_dir": f"{out.name}/{case}", "dir": out / case,
                     "figures": {n: doc["figures"][n] for n, _ in KEY_FIGURES
                                 if doc["figures"].get(n)}})
    if base is not None and base not in taken:         # before anything is written
        raise InputError(f"--base {base}: no such row (the rows: {', '.join(sorted(taken))})")
    for r in runs:
        d = r["dir"]
        if d.is_dir():                      # only what this command writes there
            for old in [*d.glob("*.png"), d / "report.json"]:
                old.unlink(missing_ok=True)
        d.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(r["input"].report_dir / "report.json", d / "report.json")
        for f in r["figures"].values():
            shrink_png(r["input"].report_dir / f, d / Path(f).name)
        r["figures"] = {n: Path(f).name for n, f in r["figures"].items()}
    command = "python -m mpipd.post " + shlex.join(argv if argv is not None else
                                                    ["validate", "--out", str(out), *args])
    md.write_text(render(runs, command, code_commit(), notes_text, base))
    stale = sorted(p.name for p in out.iterdir() if p.is_dir() and p.name not in taken)
    lines.append(f"wrote {md} and {out}/ ({', '.join(r['case'] for r in runs)})")
    if stale:
        lines.append(f"note: {out}/ also holds {', '.join(stale)}, not in this record")
    return lines
