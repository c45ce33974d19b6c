"""The worked examples (examples/*.toml, examples/README.md, docs/examples.md,
`make examples` in mk/examples.mk): every example scene passes ``mpipd check`` (serial:
check launches no MPI) without a warning and parses, and what its header promises
holds, without running it (each takes minutes: `make examples` runs them):

* the header gives the commands to check, run and draw it, with the run folder
  runs/examples/NAME and the scene's own name;
* the picture's section height (``--z``) is the one mk/examples.mk draws, and it is a
  lattice level of a part that can fail and of no charge or tube (a section through
  the rock, not through the explosive);
* examples/README.md, docs/examples.md and mk/examples.mk name every example, and
  docs/examples.md shows its picture, which exists in docs/img/examples/.
"""
import re
from pathlib import Path

import pytest
from conftest import run_cli

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = sorted((ROOT / "examples").glob("*.toml"))
NAMES = [p.stem for p in EXAMPLES]
#: the four the issue asks for (more may come)
REQUIRED = {"single_hole", "paper_charge", "two_holes_delay", "jointed_rock"}
MAKEFILE = (ROOT / "mk" / "examples.mk").read_text()


def test_the_examples_are_there():
    assert REQUIRED <= set(NAMES), f"missing: {sorted(REQUIRED - set(NAMES))}"


@pytest.mark.parametrize("path", EXAMPLES, ids=NAMES)
def test_an_example_passes_mpipd_check_without_a_warning(path):
    res = run_cli(["check", str(path.relative_to(ROOT))], cwd=ROOT, timeout=120)
    assert res.returncode == 0, res.stdout + res.stderr
    assert f"scene '{path.stem}'" in res.stdout
    assert "warning" not in (res.stdout + res.stderr).lower(), res.stdout + res.stderr


def header(path: Path) -> str:
    """The comment block at the top of the file."""
    lines = []
    for line in path.read_text().splitlines():
        if not line.startswith("#"):
            break
        lines.append(line.lstrip("# ").rstrip())
    return "\n".join(lines)


def section_height(path: Path) -> float:
    found = re.findall(r"--z ([0-9.e+-]+)", header(path))
    assert found, f"{path.name}: the header gives no --z for the picture"
    assert len(set(found)) == 1, f"{path.name}: the header gives several --z: {found}"
    return float(found[0])


@pytest.mark.parametrize("path", EXAMPLES, ids=NAMES)
def test_an_example_parses_and_its_header_gives_the_commands(path):
    from mpipd.input.scene import load
    scene, _ = load(str(path))
    name = path.stem
    assert scene.name == name                      # the default run folder is runs/NAME
    assert scene.time.t_end is not None and scene.time.n_steps > 0
    text = " ".join(header(path).replace("\\\n", " ").split())
    for command in (f"mpipd check examples/{name}.toml",
                    f"mpirun -n 2 mpipd run examples/{name}.toml --out runs/examples/{name}",
                    f"mpirun -n 2 python -m mpipd.post fracture runs/examples/{name}/run.h5",
                    f"--out runs/examples/{name}/fracture.png"):
        assert command in text, f"{path.name}: the header lacks `{command}`"
    # every table of the scene is commented: a comment line or a trailing comment in it
    assert path.read_text().count("#") > 40, f"{path.name}: too few comments"


@pytest.mark.parametrize("path", EXAMPLES, ids=NAMES)
def test_the_picture_is_a_section_through_the_rock(path):
    from mpipd.input.scene import load
    scene, _ = load(str(path))
    z = section_height(path)
    made = re.search(rf"^EXAMPLE_Z_{path.stem} := ([0-9.e+-]+)$", MAKEFILE, re.M)
    assert made, f"mk/examples.mk draws no section of {path.stem}"
    assert float(made.group(1)) == z, "mk/examples.mk and the header draw different sections"
    can_fail = [p for p in scene.parts if scene.materials[p.material].can_fail]
    others = [p for p in scene.parts if not scene.materials[p.material].can_fail]
    assert can_fail, f"{path.name}: no part that can fail"

    def on_level(part):
        return any(abs(v - z) < 1e-9 for v in part.shape.z_levels(part.dx))
    assert any(on_level(p) for p in can_fail), \
        f"--z {z} is no lattice level of {', '.join(p.name for p in can_fail)}"
    hit = [p.name for p in others if on_level(p)]
    assert not hit, f"--z {z} is also a level of {hit}: the section would show them"


def test_the_readme_the_docs_page_and_the_make_target_name_every_example():
    readme = (ROOT / "examples" / "README.md").read_text()
    page = (ROOT / "docs" / "examples.md").read_text()
    listed = re.search(r"^EXAMPLES := (.*)$", MAKEFILE, re.M).group(1).split()
    assert sorted(listed) == NAMES, "mk/examples.mk's EXAMPLES differ from examples/*.toml"
    for name in NAMES:
        assert f"{name}.toml" in readme, f"examples/README.md does not list {name}"
        assert f"examples/{name}.toml" in page, f"docs/examples.md does not show {name}"
        assert f"img/examples/{name}.png" in page, f"docs/examples.md lacks {name}'s picture"
        assert (ROOT / "docs" / "img" / "examples" / f"{name}.png").is_file(), \
            f"docs/img/examples/{name}.png is missing: make examples"
    mkdocs = (ROOT / "mkdocs.yml").read_text()
    assert "examples.md" in mkdocs, "docs/examples.md is not in mkdocs.yml's nav"
