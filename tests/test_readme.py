"""README.md stays short, true and runnable: its validation table says what the record
says, its scene of your own passes `mpipd check`, and every file it links exists."""
from __future__ import annotations

import json
import re
import subprocess
import sys
from pathlib import Path

import pytest
import tomllib
from conftest import child_env

from mpipd.post.targets import TARGETS
from mpipd.post.validation import judged

ROOT = Path(__file__).resolve().parents[1]
README = (ROOT / "README.md").read_text()


def _base_case() -> str:
    """The record's base row, as `make validate` names it (studies/validate.mk)."""
    mk = (ROOT / "studies" / "validate.mk").read_text()
    return re.search(r"^VALIDATE_BASE \?= (\S+)$", mk, re.M).group(1)


def _status_rows() -> list[tuple[str, str]]:
    """(quantity, verdict) of the README's table under "## Validation status"."""
    section = README.split("## Validation status", 1)[1].split("\n## ", 1)[0]
    rows = [line.strip("|").split("|") for line in section.splitlines()
            if line.startswith("| ") and not line.startswith("| judged")]
    return [(q.strip(), v.strip()) for q, v in rows]


def test_short():
    assert len(README.splitlines()) <= 200
    assert "§" not in README                    # no references into the research notes
    assert "/work/" not in README and "/home/" not in README


def test_status_table_is_the_records():
    """One row per judged quantity of the base row's report.json, in the record's order,
    each with the verdict the record gives it now (mpipd.post.validation.judged)."""
    doc = json.loads((ROOT / "studies" / "validation" / "record" / _base_case()
                      / "report.json").read_text())
    got = judged(doc)
    expected = [got[t.key][1] for t in TARGETS
                if t.kind in ("range", "consistency") and t.key in got]
    assert [v for _, v in _status_rows()] == expected


def test_scene_of_your_own_checks(tmp_path):
    block = re.search(r"```toml\n(.*?)```", README, re.S).group(1)
    scene = tomllib.loads(block)
    assert scene["scene"]["name"] == "my_block"
    path = tmp_path / "my_block.toml"
    path.write_text(block)
    res = subprocess.run([sys.executable, "-m", "mpipd.cli", "check", str(path)],
                         capture_output=True, text=True, timeout=300, cwd=tmp_path)
    assert res.returncode == 0, res.stderr
    assert "OK" in res.stdout


def test_links_exist():
    for target in re.findall(r"\]\(([^)#\s]+)(?:#[^)\s]*)?\)", README):
        if "://" in target:
            continue
        assert (ROOT / target).exists(), f"README links a missing file: {target}"


@pytest.mark.mpi
def test_commands_of_your_own_run_as_printed(tmp_path):
    """The README's commands after the scene of your own, run by bash as printed (the
    virtualenv's path made absolute), with no Open MPI variable in the environment:
    its own export lines are what lets mpirun run as root and on more ranks than cores."""
    scene = re.search(r"```toml\n(.*?)```", README, re.S).group(1)
    (tmp_path / "my_block.toml").write_text(scene)
    block = re.search(r"```\n(\. \.venv/bin/activate\n.*?)```", README.split(scene, 1)[1],
                      re.S).group(1)
    assert "mpirun -n 2 mpipd run my_block.toml" in block
    assert block.index("export OMPI_ALLOW_RUN_AS_ROOT=1") < block.index("mpirun")
    script = block.replace(". .venv/bin/activate", f". {ROOT / '.venv' / 'bin' / 'activate'}")
    env = {k: v for k, v in child_env().items() if not k.startswith("OMPI_")}
    res = subprocess.run(["bash", "-e", "-c", script], capture_output=True, text=True,
                         timeout=600, cwd=tmp_path, env=env)
    assert res.returncode == 0, res.stdout + res.stderr
    assert (tmp_path / "runs" / "my_block" / "run.h5").is_file()
    assert "my_block" in res.stdout
