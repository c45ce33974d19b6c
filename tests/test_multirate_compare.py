"""benchmarks/multirate_compare.py's table: target rows are matched by label, so a
report made before a row existed (studies/validation/record/<case>/report.json) shows it as
missing instead of shifting every row below it."""
import importlib.util
from pathlib import Path

spec = importlib.util.spec_from_file_location(
    "multirate_compare", Path(__file__).resolve().parents[1] / "benchmarks" / "multirate_compare.py")
mc = importlib.util.module_from_spec(spec)
spec.loader.exec_module(mc)


def _run(targets):
    return {"commit": "abc", "ranks": 2, "dt": 2e-8, "wall": 10.0, "evaluated": None,
            "modes": [0, 1, 2, 3], "broken": 5, "balance": 0.0, "multirate": 0.0,
            "targets": targets}


def test_rows_are_matched_by_label():
    old = _run([("crushed zone", "R_b", 3.0), ("PPV radius", "mm", 20.0)])
    new = _run([("crushed zone", "R_b", 4.0), ("ring arcs", "mm", 7.0),
                ("PPV radius", "mm", 30.0)])
    rows = {line.split(" | ")[0].lstrip("| "): line
            for line in mc.table({"base": old, "case": new}).splitlines()}
    assert rows["PPV radius (mm)"].endswith("| 20 | 30 (+50.0 %) |")
    assert rows["crushed zone (R_b)"].endswith("| 3 | 4 (+33.3 %) |")
    assert rows["ring arcs (mm)"].endswith("| — | 7 |")


def test_a_row_one_report_lacks_keeps_its_place_and_the_bands_align():
    old = _run([("crushed zone", "R_b", 3.0), ("PPV radius", "mm", 20.0)])
    new = _run([("crushed zone", "R_b", 4.0), ("ring arcs", "mm", 7.0),
                ("PPV radius", "mm", 30.0)])
    names = [line.split(" | ")[0].lstrip("| ")
             for line in mc.table({"base": old, "case": new}).splitlines()]
    assert names[-3:] == ["crushed zone (R_b)", "ring arcs (mm)", "PPV radius (mm)"]
    for first in ("new", "old"):            # either run first in its group
        runs = ({"g_1": new, "g_2": old, "h_1": old} if first == "new"
                else {"g_1": old, "g_2": new, "h_1": new})
        rows = {line.split(" | ")[0].lstrip("| "): line
                for line in mc.bands(runs, ["g", "h"]).splitlines()}
        assert rows["PPV radius (mm)"].startswith("| PPV radius (mm) | 20 – 30 | ")
        assert rows["crushed zone (R_b)"].startswith("| crushed zone (R_b) | 3 – 4 | ")
        assert "ring arcs (mm)" not in rows or rows["ring arcs (mm)"].count("7 – 7") == 2
