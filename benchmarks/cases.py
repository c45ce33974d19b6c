"""`make cases`: run a built-in scene and every named case of it to t_end, and tabulate
whether each got there and how physical its end state is.

    python benchmarks/cases.py [--scene blast_demo] [--ranks 2] [--out runs/cases]
                               [--only dx1.2,case3] [--mpirun mpirun]

Each run goes to ``OUT/<scene>/<case>/`` (``base`` is the scene itself) with
``mpipd run SCENE[:CASE] --overwrite``; a case whose run.h5 already ends at its last
step is not run again (delete the folder to redo it).  From each run file
(mpipd.model.ledger, the run's own /energy record and every-step peak fields) the table
gives: exit status, the last step against the scene's, the loop's wall time and
throughput (run.h5 attr ``segments``), points, failed points by mode, the closure
error of the energy ledger, impossible energies, and the largest every-step speed
of each material.  Writes ``OUT/<scene>/cases.md`` and ``cases.json``; exit status 1
if any run stopped early, blew up or has an impossible energy.
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
from pathlib import Path

import h5py
import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(ROOT))

from mpipd.input import scene as sc  # noqa: E402
from mpipd.model.ledger import Energies, impossible  # noqa: E402
from mpipd.output.writer import short_commit  # noqa: E402


def finished(h5: Path) -> bool:
    """The run file exists and its last frame is its run's last step."""
    try:
        with h5py.File(h5, "r") as f:
            return int(f.attrs["frames_written"]) == f["time"].shape[0]
    except (OSError, KeyError):
        return False


def summary(h5: Path, rc: int) -> dict:
    """The table row of one run, read from its run file."""
    with h5py.File(h5, "r") as f:
        a = f.attrs
        frames = int(a.get("frames_written", 0))
        k = frames - 1
        e = Energies.from_record(f["energy"], k)
        names = list(f["geometry/material"].attrs["names"])
        mat = f["geometry/material"][...]
        peak = f["fields/peak_speed"][k] if "peak_speed" in f["fields"] else None
        segs = json.loads(a.get("segments", "[]"))
        every = int(a["every"])
        steps = int(a["steps"])
        last = min(k * every, steps)
        failed = [int(c) for c in a.get("failed_points_by_mode", [])]
        speed = ({names[m]: float(np.nanmax(peak[mat == m])) for m in np.unique(mat)}
                 if peak is not None else {})
    wall = sum(s["wall_s"] for s in segs)
    done = sum(s["to_step"] - s["from_step"] for s in segs)
    commits = sorted({short_commit(sg["git_commit"], 10) for sg in segs})
    return {"exit": rc, "commits": commits, "last_step": last, "steps": steps, "reached_t_end": last == steps,
            "wall_s": wall if segs else None, "n_points": int(len(mat)),
            "bond_steps_per_s": (sum(s["bond_steps_per_s"] * s["wall_s"] for s in segs) / wall
                                 if wall > 0 and done else None),
            "failed_by_mode": failed, "balance": e.balance, "impossible": impossible(e),
            "peak_speed_m_s": speed}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--scene", default="blast_demo")
    ap.add_argument("--ranks", type=int, default=2)
    ap.add_argument("--out", default="runs/cases")
    ap.add_argument("--only", default="", help="comma-separated case names (base = the scene)")
    ap.add_argument("--mpirun", default=os.environ.get("MPIRUN", "mpirun"))
    args = ap.parse_args(argv)
    names = ["base", *sc.cases(args.scene)]
    if args.only:
        want = args.only.split(",")
        unknown = [w for w in want if w not in names]
        if unknown:
            print(f"cases: unknown case(s) {', '.join(unknown)} of {args.scene} "
                  f"(known: {', '.join(names)})", file=sys.stderr)
            return 2
        names = [n for n in names if n in want]
    root = Path(args.out) / args.scene
    rows = {}
    for name in names:
        out = root / name
        h5 = out / "run.h5"
        rc = 0
        if not finished(h5):
            src = args.scene if name == "base" else f"{args.scene}:{name}"
            cmd = [args.mpirun, "-n", str(args.ranks), sys.executable, "-m", "mpipd.cli", "run",
                   src, "--out", str(out), "--overwrite", "--quiet"]
            print("cases:", " ".join(cmd), flush=True)
            rc = subprocess.run(cmd, cwd=ROOT).returncode
        rows[name] = (summary(h5, rc) if h5.exists()
                      else {"exit": rc, "reached_t_end": False, "impossible": ["no run file"]})
        print(f"cases: {name}: {json.dumps(rows[name])}", flush=True)
    root.mkdir(parents=True, exist_ok=True)
    (root / "cases.json").write_text(json.dumps(rows, indent=1))
    mats = sorted({m for r in rows.values() for m in r.get("peak_speed_m_s", {})})
    L = [f"# {args.scene} and its named cases to t_end", "",
         f"Made by `python benchmarks/cases.py --scene {args.scene} --ranks {args.ranks}`.", "",
         "| case | commit | exit | last step / steps | wall (min) | points | M bond-steps/s | "
         "failed (JH2 plastic / JH2 tensile / tension) | ledger balance | impossible | "
         + " | ".join(f"peak speed {m} (m/s)" for m in mats) + " |",
         "|---|---|---|---|---|---|---|---|---|---|" + "---|" * len(mats)]
    for name, r in rows.items():
        if "steps" not in r:
            L.append(f"| {name} | — | {r['exit']} | no run file |" + " |" * (7 + len(mats)))
            continue
        f = r["failed_by_mode"]
        rate = r["bond_steps_per_s"]
        L.append(f"| {name} | {', '.join(r['commits']) or 'not recorded'} | {r['exit']} | "
                 f"{r['last_step']} / {r['steps']} | "
                 f"{'not recorded' if r['wall_s'] is None else format(r['wall_s'] / 60, '.1f')}"
                 f" | {r['n_points']} | "
                 f"{'—' if rate is None else format(rate / 1e6, '.2f')} | "
                 f"{' / '.join(map(str, f[1:])) if f else '—'} | {r['balance']:+.1e} | "
                 f"{'; '.join(r['impossible']) or 'none'} | "
                 + " | ".join(format(r['peak_speed_m_s'].get(m, float('nan')), '.4g')
                              for m in mats) + " |")
    (root / "cases.md").write_text("\n".join(L) + "\n")
    print(f"cases: wrote {root / 'cases.md'}")
    bad = [n for n, r in rows.items() if not r["reached_t_end"] or r["impossible"] or r["exit"]]
    if bad:
        print(f"cases: not through or not physical: {', '.join(bad)}", file=sys.stderr)
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
