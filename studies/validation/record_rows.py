"""The inputs of the validation record on a machine that lacks some of its run files
(`make record`, studies/validate.mk).

For each run file RUNS/<case>/run.h5 given, one input of ``mpipd.post validate``
is printed, one per line:

* ``RUNS/<case>/report``, if its report.json is there (the run's own report);
* else the run file, if it is there (``validate`` reports it first);
* else ``ROWS/<case>``: the row's committed folder ``studies/validation/record/<case>/`` at
  the repository's HEAD (report.json and figures, as the record last copied them),
  extracted with ``git archive``.  The record then names that folder as the row's
  report, so it says which rows were read back from the repository.

A row with none of the three gives one line naming it and exit status 2, and
nothing is printed.  ROWS/<case> is written afresh (this command's own folder);
nothing else is written.
"""
from __future__ import annotations

import argparse
import io
import shutil
import subprocess
import sys
import tarfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
COMMITTED = "studies/validation/record"


def committed_row(case: str, rows: Path, root: Path = ROOT) -> Path | None:
    """Extract ``studies/validation/record/<case>/`` at HEAD into ``rows/<case>``; None if HEAD
    has no report.json there."""
    path = f"{COMMITTED}/{case}"
    res = subprocess.run(["git", "-C", str(root), "archive", "--format=tar", "HEAD", path],
                         capture_output=True, timeout=120)
    if res.returncode != 0:
        return None
    dst = rows / case
    if dst.exists():
        shutil.rmtree(dst)
    dst.mkdir(parents=True)
    with tarfile.open(fileobj=io.BytesIO(res.stdout)) as tar:
        for m in tar.getmembers():
            if m.isfile():
                rel = Path(m.name).relative_to(path)
                (dst / rel).parent.mkdir(parents=True, exist_ok=True)
                (dst / rel).write_bytes(tar.extractfile(m).read())
    return dst if (dst / "report.json").is_file() else None


def inputs(run_files: list[str], rows: Path, root: Path = ROOT) -> list[str]:
    out, missing = [], []
    for rf in run_files:
        run = Path(rf)
        case = run.parent.name
        if (run.parent / "report" / "report.json").is_file():
            out.append(str(run.parent / "report"))
        elif run.is_file():
            out.append(str(run))
        else:
            got = committed_row(case, rows, root)
            if got is None:
                missing.append(f"{run} (no run file, no report beside it, and no "
                               f"{COMMITTED}/{case}/report.json at HEAD)")
            else:
                out.append(str(got))
    if missing:
        print("record_rows: missing row: " + "; ".join(missing), file=sys.stderr)
        raise SystemExit(2)
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--rows", required=True, help="folder for the rows read from git")
    ap.add_argument("run_files", nargs="+")
    a = ap.parse_args(argv)
    print("\n".join(inputs(a.run_files, Path(a.rows))))
    return 0


if __name__ == "__main__":
    sys.exit(main())
