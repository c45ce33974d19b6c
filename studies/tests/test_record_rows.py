"""studies/validation/record_rows.py: each row's input for the record, from its report, its run
file, or its committed folder at HEAD (read back from git), else exit status 2."""
import importlib.util
import json
import subprocess

import pytest
from conftest import ROOT

spec = importlib.util.spec_from_file_location("record_rows", ROOT / "studies" / "validation" / "record_rows.py")
rr = importlib.util.module_from_spec(spec)
spec.loader.exec_module(rr)


def test_each_row_from_its_report_its_run_file_or_git(tmp_path):
    runs = tmp_path / "runs"
    (runs / "a" / "report").mkdir(parents=True)
    (runs / "a" / "report" / "report.json").write_text("{}")
    (runs / "b").mkdir()
    (runs / "b" / "run.h5").write_bytes(b"")
    rows = tmp_path / "rows"
    got = rr.inputs([str(runs / "a" / "run.h5"), str(runs / "b" / "run.h5"),
                     str(runs / "demo" / "run.h5")], rows)
    assert got == [str(runs / "a" / "report"), str(runs / "b" / "run.h5"), str(rows / "demo")]
    # the demo row as committed at HEAD, file for file
    listed = subprocess.run(["git", "-C", str(ROOT), "ls-tree", "-r", "--name-only", "HEAD",
                             "studies/validation/record/demo"], capture_output=True, text=True,
                            check=True).stdout.split()
    assert sorted(p.name for p in (rows / "demo").iterdir()) == sorted(
        p.rsplit("/", 1)[1] for p in listed)
    head = subprocess.run(["git", "-C", str(ROOT), "show", "HEAD:studies/validation/record/demo/report.json"],
                          capture_output=True, check=True).stdout
    assert (rows / "demo" / "report.json").read_bytes() == head
    assert json.loads(head)["run"]["label"] == "blast_demo (demo)"


def test_a_row_found_nowhere_is_exit_2(tmp_path, capsys):
    with pytest.raises(SystemExit) as e:
        rr.inputs([str(tmp_path / "runs" / "no_such_case" / "run.h5")], tmp_path / "rows")
    assert e.value.code == 2
    err = capsys.readouterr().err
    assert "no_such_case" in err and err.count("\n") == 1
