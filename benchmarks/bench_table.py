"""README's table of `make bench` figures, made from the output of one `make bench`:

    python benchmarks/bench_table.py studies/bench_logs/make_bench_<commit>.log

reads its ``bench <case> ranks=N key=value ...`` lines (benchmarks/case.py) and the
LAMMPS peer's ``peer lammps ...`` lines (benchmarks/run.py) and prints the markdown
table: bond-steps/s per core (M) of each case on 1 and 2 ranks, the 2-rank share of
the 1-rank rate, the shares of the step the case reports, and the memory.  With
``--before OLD.log``, the table of the change instead: each case's rate in both runs.
"""
from __future__ import annotations

import argparse
import re

#: the cases of the table, in its order, and how the table names them
CASES = {"elastic": "`elastic`", "jh2": "`jh2`", "jh2_refresh": "`jh2_refresh`",
         "jh2_rockmass": "`jh2_rockmass` (jitter 0.2, Weibull m = 6)", "blast": "`blast`",
         "blast_refresh": "`blast_refresh`", "blast_mr": "`blast_mr`"}
#: the step shares a case may report, and their names in the table
SHARES = {"breakage_share": "breakage", "flag_exchange_share": "failure-flag exchange",
          "gas_research_share": "gas re-search", "interface_share": "interface correction"}


def parse(text: str) -> tuple[dict, dict]:
    """({(case, ranks): {key: value}}, {ranks: {key: value}} of the LAMMPS peer)."""
    runs, peer = {}, {}
    for line in text.splitlines():
        if line.startswith("bench "):
            name = line.split()[1]
            kv = dict(re.findall(r"(\w+)=(\S+)", line))
            runs[(name, int(kv["ranks"]))] = kv
        elif line.startswith("peer lammps"):
            kv = dict(re.findall(r"(\w+)=([^,\s]+)", line))
            peer[int(kv["ranks"])] = kv
    return runs, peer


def _m(kv: dict) -> float:
    return float(kv["bond_steps_per_s_per_core"]) / 1e6


def table(runs: dict, peer: dict) -> list[str]:
    """The markdown lines of the table."""
    out = ["| case | ranks | M bond-steps/s per core | share of the step | memory |",
           "|---|---|---|---|---|"]
    for case, label in CASES.items():
        for n in (1, 2):
            kv = runs.get((case, n))
            if kv is None:
                continue
            rate = f"**{_m(kv):.1f}**"
            if n > 1 and (case, 1) in runs:
                rate += f" ({100 * _m(kv) / _m(runs[(case, 1)]):.0f} % of 1 rank)"
            shares = ", ".join(f"{name} {100 * float(kv[k]):.1f} %" for k, name in SHARES.items()
                               if k in kv and float(kv[k]) > 0.0)
            mem = (f"{float(kv['bytes_per_bond']):.0f} B/bond + "
                   f"{float(kv['bytes_per_point']):.0f} B/point, RSS {kv['peak_rss_mib']} MiB")
            out.append(f"| {label} | {n} | {rate} | {shares} | {mem} |")
    pair = [runs.get(("blast_paper_slice", n)) for n in (1, 2)]
    if all(pair):
        s = " / ".join(f"{float(kv['single_rate_wall_s_per_us']):.2f}" for kv in pair)
        m = " / ".join(f"{float(kv['multirate_wall_s_per_us']):.2f}" for kv in pair)
        x = " / ".join(f"{float(kv['speedup']):.2f}×" for kv in pair)
        out.append(f"| `blast_paper_slice`: wall s per simulated µs | 1 / 2 | single-rate {s}, "
                   f"ratio {pair[0]['max_ratio']} {m} | speed-up {x} (bond work: "
                   f"{float(pair[0]['projected_speedup']):.2f}×) | |")
    rs = [runs.get(("restart", n)) for n in (1, 2)]
    if all(rs):
        out.append("| restore of the `jh2` block's checkpoint, "
                   f"{100 * int(rs[0]['broken_pairs']) / int(rs[0]['bonds']):.0f} % of the bonds "
                   "broken (benchmarks/restart_bench.py) | 1 / 2 | — | restore "
                   + " / ".join(f"{float(kv['restore_s']):.2f}" for kv in rs) + " s | "
                   + " / ".join(f"{kv['restore_extra_mib']}" for kv in rs)
                   + " MiB per rank above the built model |")
    if peer:
        rates = " / ".join(f"{float(peer[n]['bond_updates_per_s_per_core']) / 1e6:.1f}"
                           for n in sorted(peer))
        ranks = " / ".join(str(n) for n in sorted(peer))
        out.append(f"| LAMMPS peri/lps (the `elastic` lattice) | {ranks} | {rates} | | |")
    return out


def change(old: dict, new: dict) -> list[str]:
    """The markdown lines of the rates of two runs (``parse(...)[0]`` of each), case by case."""
    out = ["| case | ranks | before | after | change |", "|---|---|---|---|---|"]
    for case, label in CASES.items():
        for n in (1, 2):
            if (case, n) in old and (case, n) in new:
                a, b = _m(old[(case, n)]), _m(new[(case, n)])
                out.append(f"| {label} | {n} | {a:.1f} | **{b:.1f}** | {100 * (b / a - 1):+.0f} % |")
    for key, name in (("single_rate_wall_s_per_us", "single-rate"),
                      ("multirate_wall_s_per_us", "multi-rate")):
        for n in (1, 2):
            a, b = old.get(("blast_paper_slice", n)), new.get(("blast_paper_slice", n))
            if a and b:
                ta, tb = float(a[key]), float(b[key])
                out.append(f"| `blast_paper_slice` {name}, wall s per simulated µs | {n} | "
                           f"{ta:.2f} | **{tb:.2f}** | {100 * (tb / ta - 1):+.0f} % |")
    return out


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("log", help="the output of one `make bench`")
    ap.add_argument("--before", help="the output of an earlier `make bench`: print the change")
    args = ap.parse_args(argv)
    with open(args.log) as fh:
        runs, peer = parse(fh.read())
    if args.before:
        with open(args.before) as fh:
            print("\n".join(change(parse(fh.read())[0], runs)))
    else:
        print("\n".join(table(runs, peer)))


if __name__ == "__main__":
    main()
