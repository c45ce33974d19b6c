"""benchmarks/bench_table.py: README's bench table from the lines of a `make bench`."""
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
import bench_table  # noqa: E402

LOG = "\n".join([
    "bench elastic ranks=1 points=8 bonds=80 steps=20 wall_s=1.0 "
    "bond_steps_per_s_per_core=4.0e+07 bytes_per_bond=29.00 bytes_per_point=888.0 "
    "peak_rss_mib=100 setup_s=1.0",
    "bench elastic ranks=2 points=8 bonds=80 steps=20 wall_s=1.0 "
    "bond_steps_per_s_per_core=3.0e+07 bytes_per_bond=29.00 bytes_per_point=800.0 "
    "peak_rss_mib=60 setup_s=1.0 breakage_share=0.020 flag_exchange_share=0.000",
    "bench blast_paper_slice ranks=1 points=8 bonds=80 steps=20 dt=2e-08 "
    "single_rate_wall_s_per_us=12.0 multirate_wall_s_per_us=6.0 speedup=2.0 "
    "max_ratio=4 projected_speedup=3.0",
    "bench blast_paper_slice ranks=2 points=8 bonds=80 steps=20 dt=2e-08 "
    "single_rate_wall_s_per_us=7.0 multirate_wall_s_per_us=2.0 speedup=3.5 "
    "max_ratio=4 projected_speedup=3.0",
    "peer lammps peri/lps: ranks=1, particles=8, bond_updates_per_s_per_core=2.5e+07",
    "peer lammps peri/lps: ranks=2, particles=8, bond_updates_per_s_per_core=2.0e+07",
    "bench restart ranks=1 points=8 bonds=80 broken_pairs=24 build_peak_mib=100 "
    "rss_built_mib=90 restore_peak_mib=120 restore_extra_mib=30 restore_s=0.50",
    "bench restart ranks=2 points=8 bonds=80 broken_pairs=24 build_peak_mib=60 "
    "rss_built_mib=55 restore_peak_mib=70 restore_extra_mib=15 restore_s=0.25",
    "unrelated line",
])


def test_the_table_carries_each_run_of_the_log():
    lines = bench_table.table(*bench_table.parse(LOG))
    rows = {ln.split("|")[1].strip() + "/" + ln.split("|")[2].strip(): ln for ln in lines[2:]}
    assert "**40.0**" in rows["`elastic`/1"]
    assert "**30.0** (75 % of 1 rank)" in rows["`elastic`/2"]       # 30 / 40
    assert "breakage 2.0 %" in rows["`elastic`/2"] and "exchange" not in rows["`elastic`/2"]
    assert "29 B/bond + 800 B/point, RSS 60 MiB" in rows["`elastic`/2"]
    slice_row = next(ln for ln in lines if "blast_paper_slice" in ln)
    assert "single-rate 12.00 / 7.00, ratio 4 6.00 / 2.00" in slice_row
    assert "2.00× / 3.50×" in slice_row and "3.00×" in slice_row
    assert "| 25.0 / 20.0 |" in next(ln for ln in lines if "LAMMPS" in ln)
    assert not any(ln.startswith("| `jh2") for ln in lines)          # not in the log
    restore = next(ln for ln in lines if "restore of" in ln)
    assert "30 % of the bonds" in restore and "restore 0.50 / 0.25 s" in restore   # 24 / 80
    assert "30 / 15 MiB per rank" in restore


def test_the_change_between_two_logs():
    old = bench_table.parse(LOG)[0]
    new = bench_table.parse(LOG.replace("4.0e+07", "5.0e+07").replace("=12.0", "=9.0"))[0]
    lines = bench_table.change(old, new)
    assert "| `elastic` | 1 | 40.0 | **50.0** | +25 % |" in lines
    assert "| `elastic` | 2 | 30.0 | **30.0** | +0 % |" in lines
    assert any("single-rate" in ln and "| 1 | 12.00 | **9.00** | -25 % |" in ln for ln in lines)
