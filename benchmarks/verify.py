"""`make verify`: error against run time of the verification problems.

    python benchmarks/verify.py [--quick] [--out runs/verify] [--problems a,b] [--ranks 1,2]

Runs every problem of ``benchmarks/problems/`` (one module a problem, run by
``benchmarks/verify_case.py``) at its resolutions, on 1 and on 2 ranks
(``mpirun -n R``; a material-point problem only on 1), and writes to ``--out``:

* ``table.md``, ``table.csv``, ``results.json``: problem, resolution (dx, or the
  strain or time step), points, ranks, wall seconds, error measure, observed
  convergence order (against the next coarser resolution of the same problem and
  rank count), the measured value;
* ``error_vs_time.png``: log-log error against wall time, one line per problem
  (solid 1 rank, dashed 2 ranks).

It checks that each 2-rank error equals the 1-rank one (the solver is
decomposition-invariant) and prints the total wall time.  ``--quick`` runs the
two coarsest resolutions of each problem: the subset ``make test`` runs
(tests/test_verify.py).  Exit status 1 if a case failed or 1 and 2 ranks disagree.
"""
from __future__ import annotations

import argparse
import csv
import json
import math
import os
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
CASE = HERE / "verify_case.py"

#: problems in table order; "serial": a material point, run on 1 rank only
PROBLEMS = [("wave", False), ("lame", False), ("energy", False), ("jh2_point", True),
            ("detonation", False), ("isentrope_dt", False), ("wave_multirate", False),
            ("borehole_multirate", False), ("kalthoff_winkler", False)]

#: problems --quick runs on 1 rank only (the detonation run already covers the gas on 2)
QUICK_SERIAL_ONLY = {"isentrope_dt"}

#: problems --quick leaves out (tests/test_multirate.py runs the class boundary in make test,
#: tests/test_kalthoff_winkler.py a coarse Kalthoff-Winkler on 1, 2 and 3 ranks)
QUICK_SKIP = {"wave_multirate", "borehole_multirate", "kalthoff_winkler"}


def child_env() -> dict:
    """Open MPI may run as root and oversubscribe; drop launcher variables a parent
    that initialised MPI as a singleton left in the environment (they would make the
    child mpirun fail)."""
    drop = ("PMIX_", "OMPI_MCA_ess", "OMPI_MCA_orte", "OMPI_MCA_pmix", "OMPI_COMM_WORLD",
            "OMPI_FIRST", "OMPI_APP", "OMPI_UNIVERSE", "OMPI_NUM_APP", "OMPI_FILE_LOCATION")
    env = {k: v for k, v in os.environ.items() if not k.startswith(drop)}
    env.update(OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
               OMPI_MCA_rmaps_base_oversubscribe="1", OMP_NUM_THREADS="1")
    return env


def run_problem(key: str, ranks: int, quick: bool, mpirun: str, timeout: float,
                res: str | None = None) -> tuple:
    """Run ``verify_case.py KEY`` (KEY may list several problems) under mpirun."""
    cmd = [mpirun, "--oversubscribe", "-n", str(ranks), sys.executable, str(CASE), key]
    if quick:
        cmd.append("--quick")
    if res is not None:
        cmd += ["--res", res]
    t0 = time.perf_counter()
    res = subprocess.run(cmd, capture_output=True, text=True, env=child_env(), timeout=timeout)
    elapsed = time.perf_counter() - t0
    rows = [json.loads(ln[len("VERIFY "):]) for ln in res.stdout.splitlines()
            if ln.startswith("VERIFY ")]
    return rows, res, elapsed


def add_orders(rows: list) -> None:
    """Observed order p = log(e_coarse / e_fine) / log(h_coarse / h_fine) between
    consecutive resolutions of one (problem row, ranks)."""
    groups = {}
    for r in rows:
        groups.setdefault((r["problem"], r["ranks"]), []).append(r)
    for g in groups.values():
        g.sort(key=lambda r: -r["dx"])
        g[0]["order"] = None
        for a, b in zip(g, g[1:]):
            ok = (a["error"] > 0 and b["error"] > 0 and a["dx"] != b["dx"]
                  and significant(a) and significant(b))
            b["order"] = (math.log(a["error"] / b["error"]) / math.log(a["dx"] / b["dx"])
                          if ok else None)


def significant(r: dict) -> bool:
    """A measured drift smaller than twice its standard error is noise: no order from it."""
    return "value_se" not in r or abs(r["value"]) > 2.0 * r["value_se"]


def rank_agreement(rows: list) -> float:
    """Largest difference between the 2-rank and the 1-rank error of a case, relative to
    1e-9 |e| + 1e-12: the fields are bit-identical, but global sums (energies) are
    reduced in another order, which moves a tiny drift slope by ~1e-15 absolute.
    Above 1 means the decomposition changed an answer."""
    one = {(r["problem"], r["dx"]): r["error"] for r in rows if r["ranks"] == 1}
    worst = 0.0
    for r in rows:
        if r["ranks"] != 1 and (r["problem"], r["dx"]) in one:
            e1 = one[(r["problem"], r["dx"])]
            worst = max(worst, abs(r["error"] - e1) / (1e-9 * abs(e1) + 1e-12))
    return worst


def fmt_res(r: dict) -> str:
    if "resolution" in r:
        return r["resolution"]
    if r["key"] == "isentrope_dt":
        return f"dt {r['dx']:.3g} s"
    return f"{r['dx'] * 1e3:.3g} mm"


def fmt_value(r: dict) -> str:
    v = r.get("value")
    if v is None:
        return ""
    name = r.get("value_name", "")
    if "value_se" in r:
        return f"{name} {v:+.2e} ± {r['value_se']:.1e}"
    if isinstance(v, float) and (abs(v) >= 1e4 or (abs(v) < 1e-2 and v != 0)):
        return f"{name} {v:.3e}"
    return f"{name} {v:.5g}"


def write_outputs(rows: list, out: Path, total: float, quick: bool) -> str:
    out.mkdir(parents=True, exist_ok=True)
    cols = ["problem", "resolution", "points", "ranks", "wall_s", "error", "order", "measure",
            "value"]
    with open(out / "table.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(cols)
        for r in rows:
            w.writerow([r["problem"], fmt_res(r), r["points"], r["ranks"], f"{r['wall_s']:.3f}",
                        f"{r['error']:.6e}", "" if r.get("order") is None else f"{r['order']:.3f}",
                        r.get("measure", ""), fmt_value(r)])
    (out / "results.json").write_text(json.dumps({"total_wall_s": total, "quick": quick,
                                                  "rows": rows}, indent=1))
    lines = ["| problem | resolution | points | ranks | wall s | error | order | error measure | measured |",
             "|---|---|---|---|---|---|---|---|---|"]
    last = None

    def md(text):
        return str(text).replace("|", "\\|")

    for r in rows:
        name = r["problem"] if r["problem"] != last else ""
        last = r["problem"]
        order = ("n.s." if not significant(r) else
                 "" if r.get("order") is None else f"{r['order']:.2f}")
        lines.append(f"| {md(name)} | {fmt_res(r)} | {r['points']} | {r['ranks']} | "
                     f"{r['wall_s']:.2f} | {r['error']:.2e} | {order} | "
                     f"{md(r.get('measure', '')) if name else ''} | {md(fmt_value(r))} |")
    text = "\n".join(lines) + "\n"
    (out / "table.md").write_text(text)
    (out / "summary.md").write_text(summary(rows, total))
    plot(rows, out / "error_vs_time.png")
    return text


def summary(rows: list, total: float) -> str:
    """One row per problem and resolution, the 1- and 2-rank wall times side by side
    (the errors agree): the table the README shows."""
    lines = ["| problem | resolution | points | wall s, 1 / 2 ranks | error | order |",
             "|---|---|---|---|---|---|"]
    seen = {}
    for r in rows:
        seen.setdefault((r["problem"], r["dx"]), {})[r["ranks"]] = r
    last = None
    for (problem, _), by in seen.items():
        r = by.get(1) or next(iter(by.values()))
        two = f"{by[2]['wall_s']:.1f}" if 2 in by else "-"
        order = ("n.s." if not significant(r) else
                 "" if r.get("order") is None else f"{r['order']:.2f}")
        name = problem if problem != last else ""
        last = problem
        lines.append(f"| {name} | {fmt_res(r)} | {r['points']} | {r['wall_s']:.1f} / {two} | "
                     f"{r['error']:.2e} | {order} |")
    lines.append(f"\n`make verify`: {total / 60:.1f} min in all.")
    return "\n".join(lines) + "\n"


def plot(rows: list, path: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(8, 5.5))
    names = list(dict.fromkeys(r["problem"] for r in rows))
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    for k, name in enumerate(names):
        for ranks, style in ((1, "-o"), (2, "--s")):
            g = sorted((r for r in rows if r["problem"] == name and r["ranks"] == ranks),
                       key=lambda r: r["wall_s"])
            g = [r for r in g if r["error"] > 0]
            if not g:
                continue
            ax.loglog([max(r["wall_s"], 1e-4) for r in g], [r["error"] for r in g], style,
                      color=colours[k % len(colours)], ms=4,
                      label=f"{name}: {g[0].get('measure', '')}" if ranks == 1 else None)
    ax.set_xlabel("wall time per case (s)")
    ax.set_ylabel("error (see the table for each measure)")
    ax.set_title("mpipd: error against run time (solid 1 rank, dashed 2 ranks)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7, loc="best")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true", help="the two coarsest resolutions only")
    ap.add_argument("--out", default="runs/verify")
    ap.add_argument("--problems", default=",".join(k for k, _ in PROBLEMS))
    ap.add_argument("--ranks", default="1,2")
    ap.add_argument("--mpirun", default=os.environ.get("MPIRUN", "mpirun"))
    ap.add_argument("--timeout", type=float, default=1800.0, help="per problem and rank count")
    ap.add_argument("--from-json", metavar="RESULTS", default=None,
                    help="rewrite the tables and the plot from a results.json, run nothing")
    args = ap.parse_args(argv)
    if args.from_json:
        data = json.loads(Path(args.from_json).read_text())
        print(write_outputs(data["rows"], Path(args.out), data["total_wall_s"], data["quick"]))
        return 0
    wanted = args.problems.split(",")
    unknown = set(wanted) - {k for k, _ in PROBLEMS}
    if unknown:
        ap.error(f"unknown problem(s): {', '.join(sorted(unknown))}")
    t0 = time.perf_counter()
    rows, status = [], 0
    jobs = []
    for ranks in map(int, args.ranks.split(",")):
        keys = [k for k, serial in PROBLEMS if k in wanted and not (serial and ranks != 1)]
        if args.quick:
            # one process per rank count; on 2+ ranks only the coarsest resolution, which
            # is enough to check that the decomposition does not change the answer
            keys = [k for k in keys if (ranks == 1 or k not in QUICK_SERIAL_ONLY)
                    and k not in QUICK_SKIP]
            if keys:
                jobs.append((",".join(keys), ranks, None if ranks == 1 else "0"))
        else:
            jobs += [(k, ranks, None) for k in keys]
    for key, ranks, res_idx in jobs:
        got, res, elapsed = run_problem(key, ranks, args.quick, args.mpirun, args.timeout,
                                        res_idx)
        print(f"verify: {key} on {ranks} rank(s): {len(got)} row(s) in {elapsed:.1f} s",
              flush=True)
        if res.returncode or not got:
            status = 1
            sys.stderr.write(f"verify: {key} on {ranks} rank(s) failed "
                             f"(exit {res.returncode}):\n{res.stderr[-3000:]}\n")
        rows.extend(got)
    total = time.perf_counter() - t0
    order = {k: i for i, (k, _) in enumerate(PROBLEMS)}
    rows.sort(key=lambda r: (order[r["key"]], r["problem"], r["ranks"], -r["dx"]))
    add_orders(rows)
    table = write_outputs(rows, Path(args.out), total, args.quick)
    agree = rank_agreement(rows)
    print(table)
    print(f"verify: 2-rank errors equal the 1-rank ones (largest difference {agree:.2g} of "
          f"1e-9 |error| + 1e-12)")
    print(f"verify: total {total:.1f} s; wrote {args.out}/table.md, table.csv, results.json, "
          f"error_vs_time.png")
    if agree > 1.0:
        print("verify: error: 1 and 2 ranks disagree", file=sys.stderr)
        status = 1
    return status


if __name__ == "__main__":
    sys.exit(main())
