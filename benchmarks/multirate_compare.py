"""Multi-rate against single-rate on one scene: the table docs/multirate.md cites.

    python benchmarks/multirate_compare.py --out FILE.md LABEL=RUN_DIR [LABEL=RUN_DIR ...]

Each RUN_DIR holds ``run.h5`` and, for the target rows, ``report/report.json``
(``python -m mpipd.post report``; without it the table has the run rows only), or
only a ``report.json`` (a run whose file is elsewhere: ``studies/validation/record/<case>/``).
The first run is the reference.  The table gives, for every run:

* its commit, ranks and loop wall time (run.h5 ``segments``);
* the failed points by mode and the bonds broken;
* the ledger's balance and its ``multirate`` term at the end;
* every target value of the report (wave speed from first arrivals, the peak
  radial stresses, n, crack density per zone, radial cracks, crushed zone, PPV
  distance, peak pressures), with the difference from the reference in %.

Put a second single-rate run at dt/2 beside them: its differences from the
reference are the single-rate run's own time-step sensitivity, which is what a
multi-rate difference should be judged against.

``--bands sr,mr4`` adds a second table: the runs are grouped by the part of their
label before the last ``_`` (``sr_96``, ``sr_104`` … form the group ``sr``), and for
every quantity it gives each group's range (min – max over its runs) and whether
the groups' ranges overlap.  Single-rate runs at several dt spread a fracture
quantity by as much as the time step alone moves it; a multi-rate range inside
that spread is a difference no larger than a change of dt makes.
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import h5py
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from mpipd.output.writer import short_commit  # noqa: E402
from mpipd.post.validation import evaluated_share  # noqa: E402


def read(run_dir: Path) -> dict:
    if not (run_dir / "run.h5").exists() and (run_dir / "report.json").exists():
        return read_report(run_dir / "report.json")
    with h5py.File(run_dir / "run.h5", "r") as f:
        seg = json.loads(f.attrs["segments"])
        out = {"commit": short_commit(f.attrs["git_commit"]), "ranks": int(f.attrs["ranks"]),
               "wall": sum(s["wall_s"] for s in seg), "dt": float(f.attrs["dt"]),
               "modes": [int(m) for m in f.attrs["failed_points_by_mode"]],
               "broken": int(f.attrs["bonds_broken"]),
               "balance": float(f["energy/balance"][-1]),
               "multirate": float(f["energy/multirate"][-1]) if "energy/multirate" in f else 0.0,
               "evaluated": evaluated(seg)}
    rep = run_dir / "report" / "report.json"
    j = json.loads(rep.read_text()) if rep.exists() else {}
    out["targets"] = [(t["label"], t.get("unit", ""), t.get("value"))
                      for t in j.get("targets", [])] + lattice_rows(j)
    return out


def evaluated(segments) -> float | None:
    """mpipd.post.validation.evaluated_share, rounded for the table."""
    share = evaluated_share(segments)
    return None if share is None else round(share, 4)


def lattice_rows(report: dict) -> list[tuple[str, str, object]]:
    """The lattice-bias measure (mpipd.post.lattice_bias) as target-like rows: a4, a8
    and the major radial cracks, each the mean over the report's sections."""
    lb = report.get("lattice_bias")
    if not isinstance(lb, dict):
        return []
    secs = [v for v in lb.values() if isinstance(v, dict) and "a4" in v]
    if not secs:
        return []
    mean = lambda k: float(np.mean([s[k] for s in secs]))      # noqa: E731
    return [("lattice bias a4, mean over sections", "", mean("a4")),
            ("lattice bias a8, mean over sections", "", mean("a8")),
            ("noise level of a4/a8, mean over sections", "", mean("noise")),
            ("major radial cracks, mean over sections", "", mean("major_radial_cracks"))]


def read_report(path: Path) -> dict:
    """The same rows from a report.json alone (a run whose run file is not on this
    machine, e.g. studies/validation/record/<case>/report.json): its ``run`` block, failure
    modes and ledger."""
    j = json.loads(path.read_text())
    run, fm = j["run"], j["failure_modes"]
    modes = [fm.get(k, 0) for k in ("intact", "JH2 plastic (D >= 1)", "JH2 tensile (p < -T)",
                                     "tension model (Eq. 38)")]
    return {"from_report": True,
            "commit": short_commit(run["git_commit"]), "ranks": int(run["run_ranks"]),
            "wall": sum(s["wall_s"] for s in run.get("segments", [])), "dt": float(run["dt_s"]),
            "modes": modes, "broken": int(run["bonds_broken"]),
            "balance": float(j["energy_ledger"]["balance"][-1]),
            "multirate": float(j["energy_ledger"]["final_J"].get("multirate", 0.0)),
            "evaluated": evaluated(run.get("segments", [])),
            "targets": [(t["label"], t.get("unit", ""), t.get("value")) for t in j["targets"]]
            + lattice_rows(j)}


def sources(runs: dict) -> str:
    """Where the run rows come from: run.h5, or a directory's report.json alone."""
    alone = [label for label, r in runs.items() if r.get("from_report")]
    if not alone:
        return "Run rows from run.h5"
    if len(alone) == len(runs):
        return "Run rows from each directory's report.json (no run.h5 beside it)"
    return "Run rows from run.h5, and from report.json alone for " + ", ".join(alone)


def pct(v, ref):
    if not isinstance(v, (int, float)) or not isinstance(ref, (int, float)) or ref == 0:
        return ""
    return f" ({100.0 * (v - ref) / abs(ref):+.1f} %)"


def fmt(v):
    if isinstance(v, float):
        return f"{v:.4g}"
    return "—" if v is None else str(v)


def table(runs: dict) -> str:
    labels = list(runs)
    head = "| quantity | " + " | ".join(labels) + " |\n|---|" + "---|" * len(labels) + "\n"
    rows = []

    def row(name, get, diff=True):
        vals = [get(runs[k]) for k in labels]
        r0 = vals[0]
        rows.append(f"| {name} | " + " | ".join(
            fmt(v) + (pct(v, r0) if i and diff else "") for i, v in enumerate(vals)) + " |")
    row("commit", lambda r: r["commit"], False)
    row("ranks", lambda r: r["ranks"], False)
    row("dt (s)", lambda r: r["dt"], False)
    row("loop wall time (s)", lambda r: round(r["wall"], 1))
    row("bond states evaluated (of single-rate's)", lambda r: r["evaluated"])
    row("failed: JH2 plastic", lambda r: r["modes"][1])
    row("failed: JH2 tensile", lambda r: r["modes"][2])
    row("failed: tension model", lambda r: r["modes"][3])
    row("bonds broken", lambda r: r["broken"])
    row("ledger balance at the end", lambda r: r["balance"])
    row("ledger multirate term (J)", lambda r: r["multirate"])
    for name in merged_names(runs.values(), target_names):
        row(name, lambda r, name=name: dict(target_names(r)).get(name))
    return head + "\n".join(rows) + "\n"


def target_names(r) -> list[tuple[str, object]]:
    """(row name, value) of a run's target rows."""
    return [(f"{label} ({unit})" if unit else label, v) for label, unit, v in r["targets"]]


def merged_names(runs, rows) -> list[str]:
    """The row names of every run, each once, matched by name (a row one report lacks,
    made before the row existed, is None there): in the first run's order, a name
    another run adds placed after the name it follows in that run."""
    out: list[str] = []
    for r in runs:
        prev = None
        for name, _ in rows(r):
            if name not in out:
                out.insert(out.index(prev) + 1 if prev is not None else 0, name)
            prev = name
    return out


def quantities(r) -> list[tuple[str, object]]:
    """(name, value) of the numbers the band table compares."""
    out = [("bond states evaluated (of single-rate's)", r["evaluated"]),
           ("failed: JH2 plastic", r["modes"][1]), ("failed: tension model", r["modes"][3]),
           ("bonds broken", r["broken"]), ("ledger balance at the end", r["balance"])]
    return out + target_names(r)


def bands(runs: dict, groups: list[str], stats: bool = False) -> str:
    """Each group's range per quantity (with ``stats``: also mean ± sample standard
    deviation) and whether the ranges overlap."""
    members = {g: [k for k in runs if k.rpartition("_")[0] == g] for g in groups}
    empty = [g for g, m in members.items() if not m]
    if empty:
        raise SystemExit(f"multirate_compare: no run label starts with {empty[0]!r}_")
    head = ("| quantity | " + " | ".join(f"{g} ({len(members[g])} runs)" for g in groups)
            + " | ranges overlap |\n|---|" + "---|" * (len(groups) + 1) + "\n")
    names = merged_names([runs[k] for g in groups for k in members[g]], quantities)
    rows = []
    for name in names:
        rng = []
        for g in groups:
            vals = [dict(quantities(runs[k])).get(name) for k in members[g]]
            vals = [float(v) for v in vals if isinstance(v, (int, float))]
            rng.append((min(vals), max(vals), vals) if vals else None)
        if any(x is None for x in rng):
            continue
        lo, hi = max(a for a, _, _ in rng), min(b for _, b, _ in rng)

        def cell(a, b, v):
            if not stats:
                return f"{a:.4g} – {b:.4g}"
            if len(v) == 1:
                return f"{v[0]:.4g}"
            return f"{np.mean(v):.4g} ± {np.std(v, ddof=1):.2g} ({a:.4g} – {b:.4g})"
        rows.append(f"| {name} | " + " | ".join(cell(*r) for r in rng)
                    + f" | {'yes' if lo <= hi else 'no'} |")
    return head + "\n".join(rows) + "\n"


def main(argv=None):
    ap = argparse.ArgumentParser()
    ap.add_argument("runs", nargs="+", help="LABEL=RUN_DIR (the first is the reference)")
    ap.add_argument("--out", required=True)
    ap.add_argument("--bands", help="comma-separated label groups (LABEL = GROUP_SUFFIX): "
                                    "each group's range per quantity")
    ap.add_argument("--stats", action="store_true",
                    help="the band table also gives each group's mean ± standard deviation")
    ap.add_argument("--title", default="", help="a first line for the table's file")
    args = ap.parse_args(argv)
    runs = {}
    for item in args.runs:
        label, _, path = item.partition("=")
        runs[label] = read(Path(path))
    text = ((args.title + "\n\n" if args.title else "")
            + "Made by `python benchmarks/multirate_compare.py` from the run directories "
            + ", ".join(f"`{item.partition('=')[2]}`" for item in args.runs)
            + f"; the reference is {list(runs)[0]}.  {sources(runs)}, then the report's "
            "targets (mpipd.post report) where the runs have one; in brackets the "
            "difference from the reference.\n\n"
            + table(runs))
    if args.bands:
        text += ("\nRanges over each group of runs (label before the last `_`)"
                 + (", mean ± sample standard deviation (range)" if args.stats else "")
                 + ", and whether the ranges overlap:\n\n"
                 + bands(runs, args.bands.split(","), args.stats))
    Path(args.out).write_text(text)
    sys.stdout.write(text)
    return 0


if __name__ == "__main__":
    np.seterr(all="ignore")
    sys.exit(main())
