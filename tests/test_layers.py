"""The package's layers (docs/architecture.md): an import inside mpipd/ may only go
down the list cli/check/post -> solver -> model -> materials/parallel -> input -> output ->
kernels/state.  ``mpipd.post`` reads run files after a run: it sits on top beside the
CLI, may import anything below, and nothing below may import it.  The arrows still
going up are listed here by name, so that a new one fails and a removed one is noticed."""
import ast
from pathlib import Path

PKG = Path(__file__).resolve().parents[1] / "mpipd"
RANK = {"cli": 0, "check": 0, "post": 0, "solver": 1, "model": 2, "materials": 3, "parallel": 3,
        "input": 4, "output": 5, "kernels": 6, "state": 6}
#: known upward arrows, each to be removed (issue 62, item 6): the writer reads the
#: scene's field table and the ledger's terms; the scene parser reads the material
#: registry
KNOWN = {("output", "input"), ("output", "model"), ("input", "materials")}


def imports(path: Path, pkg: list[str]):
    """The mpipd modules (dotted, under mpipd) that ``path`` imports."""
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom):
            if node.level == 0:
                if node.module and node.module.startswith("mpipd."):
                    yield node.module.split(".")[1:]
                continue
            base = pkg[:len(pkg) - (node.level - 1)] + (node.module.split(".") if node.module else [])
            yield from ([base] if base else [[a.name] for a in node.names])
        elif isinstance(node, ast.Import):
            yield from (a.name.split(".")[1:] for a in node.names if a.name.startswith("mpipd."))


def upward() -> set:
    out = set()
    for f in sorted(PKG.rglob("*.py")):
        parts = list(f.relative_to(PKG).with_suffix("").parts)
        me = parts[0]
        if me not in RANK:
            continue                            # the package's __init__
        for t in imports(f, parts[:-1]):
            if t and t[0] in RANK and RANK[t[0]] < RANK[me]:
                out.add((me, t[0], ".".join(parts), ".".join(t)))
    return out


def test_no_new_arrow_up_the_layers():
    found = upward()
    new = sorted(f"{m} -> {t}" for a, b, m, t in found if (a, b) not in KNOWN)
    assert not new, "imports up the layers: " + "; ".join(new)


def test_known_arrows_still_exist():
    """A known arrow that is gone is struck from KNOWN (the list stays true)."""
    pairs = {(a, b) for a, b, _, _ in upward()}
    assert KNOWN <= pairs, f"no longer imported up: {sorted(KNOWN - pairs)}"
