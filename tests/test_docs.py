"""The documentation site (docs/, mkdocs.yml; `make docs`): it builds strict, and the
generated scene reference covers every key and every registered kind.

* the strict build: a broken link, anchor, snippet or mkdocstrings reference, an
  unknown ``<!-- mpipd:NAME -->`` marker or a failing generator fails it;
* every kind of every registry a scene resolves (materials, shapes, initial and
  boundary conditions, loads, strength distributions) has a docstring of its own, the
  kind's text in the reference;
* every numeric key has a unit in docs/gen_scene_reference.py's tables, and the tables
  name no key that no longer exists;
* docs/reference/output.md names every output field, ledger term and probe quantity;
* the tutorial's scene passes ``mpipd check``.
"""
import dataclasses
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest
from conftest import run_cli

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
sys.path.insert(0, str(DOCS))

import gen_scene_reference as gen  # noqa: E402

MKDOCS = Path(sys.executable).parent / "mkdocs"


def test_the_site_builds_strict_without_warnings(tmp_path):
    if not MKDOCS.exists():
        pytest.fail(f"{MKDOCS} is missing: `make install` installs the docs extra "
                    "(pyproject.toml) into the venv")
    env = dict(os.environ, NO_MKDOCS_2_WARNING="1")
    res = subprocess.run([str(MKDOCS), "build", "--strict", "--site-dir", str(tmp_path / "site")],
                         cwd=ROOT, capture_output=True, text=True, timeout=300, env=env)
    log = res.stdout + res.stderr
    assert res.returncode == 0, log
    assert "WARNING" not in log, log
    html = (tmp_path / "site" / "reference" / "scene" / "index.html").read_text()
    assert "mpipd:scene-reference" not in html            # the marker was filled in
    for registry in gen.registries():
        for name in registry.names():
            assert f'{registry.tag} = "{name}"' in html.replace("&quot;", '"'), name


def test_every_registered_kind_has_its_own_docstring():
    registries = gen.registries()
    assert {r.tag for r in registries} >= {"model", "kind", "distribution"}
    missing = [f"{r.what} {n!r} ({r.get(n).__module__}.{r.get(n).__qualname__})"
               for r in registries for n in r.names() if not gen.own_doc(r.get(n))]
    assert not missing, "registered without a docstring: " + "; ".join(missing)


def test_every_numeric_key_has_a_unit():
    missing = [f"{cls.__name__}.{k.name}" for cls in gen.schema_classes()
               for k in gen.keys(cls) if gen.numeric(k) and gen.unit(k) is None]
    assert not missing, ("numeric scene keys without a unit in docs/gen_scene_reference.py's "
                         "UNITS: " + ", ".join(missing))


def test_the_unit_tables_name_existing_keys():
    classes = gen.schema_classes()
    declared = {(c.__name__, f.name) for cls in classes for c in cls.__mro__
                if dataclasses.is_dataclass(c) for f in dataclasses.fields(c)}
    stale = [f"{c}.{k}" for (c, k) in gen.UNITS if (c, k) not in declared]
    assert not stale, "UNITS names keys that do not exist: " + ", ".join(stale)
    names = {k.name for cls in classes for k in gen.keys(cls)}
    assert not set(gen.UNITS_BY_NAME) - names
    for (c, k) in {**gen.ALLOWED, **gen.SEE}:
        assert (c, k) in declared, f"{c}.{k}"


def test_the_generated_reference_is_complete():
    text = gen.render()
    for cls in gen.schema_classes()[1:]:            # the Scene's own keys are the outline
        for k in gen.keys(cls):
            assert f"| `{k.name}` |" in text, f"{cls.__name__}.{k.name}"
    anchors = set(re.findall(r"\{#([\w-]+)\}", text))
    for link in re.findall(r"\]\(#([\w-]+)\)", text):
        assert link in anchors, link


def test_the_output_reference_names_every_field_term_and_quantity():
    from mpipd.input.scene import OUTPUT_FIELDS
    from mpipd.model.ledger import TERMS
    from mpipd.output.probes import QUANTITIES
    text = (DOCS / "reference" / "output.md").read_text()
    for name in [*OUTPUT_FIELDS, *TERMS, *QUANTITIES]:
        assert f"`{name}`" in text or f"/energy/{name}" in text, name


def test_the_tutorial_scene_checks():
    res = run_cli(["check", str(DOCS / "examples" / "granite_disc.toml")], timeout=120)
    assert res.returncode == 0, res.stdout + res.stderr
    assert "warning" not in res.stdout.lower(), res.stdout
