"""docs/architecture.md's ownership table says what the State registry says: each
listed array is registered, by the owner the table names, exchanged and
checkpointed as the table says (a table that drifts from the code fails here)."""
import re
from pathlib import Path

import pytest
from conftest import SCENES

from mpipd.input import scene as sc
from mpipd.solver import Simulation

DOC = Path(__file__).resolve().parents[1] / "docs" / "architecture.md"
#: the reduced blast_demo of tests/test_state.py: every model of the table exists in it
#: (gas, failure, interface correction, peaks, step classes)
OVER = dict(SCENES)["blast_demo"]


def table_rows():
    text = DOC.read_text()
    part = text.split("## Who owns which array", 1)[1].split("\n## ", 1)[0]
    rows = []
    for line in part.splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if len(cells) != 5 or cells[0] in ("array", "---") or set(cells[0]) <= set("-"):
            continue
        names = re.findall(r"`([^`]+)`", cells[0])
        rows.append((names, *cells[1:]))
    return rows


def test_table_is_not_empty():
    assert len(table_rows()) >= 15


@pytest.fixture(scope="module")
def state(team):
    scene, _ = sc.load("blast_demo", OVER)
    assert scene.time.multirate.max_ratio > 1           # the "with multi-rate" rows apply
    return Simulation(scene, team).state


#: cells that hold in a multi-rate scene (the fixture's)
WITH_MULTIRATE = "yes, with multi-rate"


@pytest.mark.parametrize("row", table_rows(), ids=lambda r: r[0][0])
def test_row_matches_registry(state, row):
    names, owner, rows, exchanged, checkpoint = row
    for name in names:
        if "<" in name:                                  # per material, or per class
            stem = name.split("<", 1)[0]
            assert any(k.startswith(stem) for k in state.fields), name
            continue
        assert name in state.fields, f"{name}: not registered"
        f = state.fields[name]
        assert f.owner == owner, (name, f.owner, owner)
        if exchanged.startswith(WITH_MULTIRATE):
            assert f.exchanged, name
        elif not exchanged.startswith("yes,"):           # "yes, if ...": scene-dependent
            assert f.exchanged == exchanged.startswith("yes"), (name, f.exchanged, exchanged)
        if checkpoint.startswith(WITH_MULTIRATE):
            assert f.checkpoint, name
        elif checkpoint.startswith("yes"):
            assert f.checkpoint, name
            phase = {"(after initialize)": "last", "(after the rebuild)": "rebuilt"}
            want = next((v for k, v in phase.items() if k in checkpoint), "state")
            assert f.restore == want, (name, f.restore, want)
        else:
            assert not f.checkpoint, name
