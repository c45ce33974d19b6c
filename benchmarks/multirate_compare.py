"""Multi-rate against single-rate on one scene: the table docs/multirate.md cites.

    python benchmarks/multirate_compare.py --out FILE.md LABEL=RUN_DIR [LABEL=RUN_DIR ...]

Each RUN_DIR holds ``run.h5`` and, for the target rows, ``report/report.json``
(``python -m postprocess report``; without it the table has the run rows only).
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
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import h5py
import numpy as np


def read(run_dir: Path) -> dict:
    with h5py.File(run_dir / "run.h5", "r") as f:
        seg = json.loads(f.attrs["segments"])
        out = {"commit": str(f.attrs["git_commit"])[:12], "ranks": int(f.attrs["ranks"]),
               "wall": sum(s["wall_s"] for s in seg), "dt": float(f.attrs["dt"]),
               "modes": [int(m) for m in f.attrs["failed_points_by_mode"]],
               "broken": int(f.attrs["bonds_broken"]),
               "balance": float(f["energy/balance"][-1]),
               "multirate": float(f["energy/multirate"][-1]) if "energy/multirate" in f else 0.0}
    rep = run_dir / "report" / "report.json"
    out["targets"] = ([(t["label"], t.get("unit", ""), t.get("value"))
                       for t in json.loads(rep.read_text())["targets"]] if rep.exists() else [])
    return out


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
    ref = runs[labels[0]]
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
    row("failed: JH2 plastic", lambda r: r["modes"][1])
    row("failed: JH2 tensile", lambda r: r["modes"][2])
    row("failed: tension model", lambda r: r["modes"][3])
    row("bonds broken", lambda r: r["broken"])
    row("ledger balance at the end", lambda r: r["balance"])
    row("ledger multirate term (J)", lambda r: r["multirate"])
    for k, (label, unit, _) in enumerate(ref["targets"]):
        row(f"{label} ({unit})" if unit else label,
            lambda r, k=k: r["targets"][k][2] if k < len(r["targets"]) else None)
    return head + "\n".join(rows) + "\n"


def main(argv=None):
    ap = argparse.ArgumentParser()
    ap.add_argument("runs", nargs="+", help="LABEL=RUN_DIR (the first is the reference)")
    ap.add_argument("--out", required=True)
    args = ap.parse_args(argv)
    runs = {}
    for item in args.runs:
        label, _, path = item.partition("=")
        runs[label] = read(Path(path))
    text = ("Made by `python benchmarks/multirate_compare.py` from the run directories "
            + ", ".join(f"`{item.partition('=')[2]}`" for item in args.runs)
            + f"; the reference is {list(runs)[0]}.  Run rows from run.h5, then the report's "
            "targets (postprocess report) where the runs have one; in brackets the "
            "difference from the reference.\n\n"
            + table(runs))
    Path(args.out).write_text(text)
    sys.stdout.write(text)
    return 0


if __name__ == "__main__":
    np.seterr(all="ignore")
    sys.exit(main())
