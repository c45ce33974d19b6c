"""What a user reads first: ``mpipd --help`` (every subcommand, plain text) and
``mpipd scenes --show NAME[:CASE]`` (a built-in scene's TOML, where it lives, a case's
overrides); the output of ``--show``, saved to a file, is the same scene."""
import shlex

from conftest import one_error, run_cli

from mpipd import cli
from mpipd.input import scene as sc


def test_help_lists_every_subcommand_in_plain_text():
    res = run_cli(["--help"])
    assert res.returncode == 0, res.stderr
    commands = cli._parser()._subparsers._group_actions[0].choices
    assert set(commands) == {"run", "check", "scenes", "cases"}
    usage = res.stdout.split("commands:", 1)[1]          # the plain-text list after the options
    for name in commands:
        assert f"mpipd {name}" in usage, name
    assert "mpipd scenes --show" in usage
    for rst in ("``", ":data:", ":func:", ".. "):          # no reStructuredText markup
        assert rst not in res.stdout, rst
    assert "OMPI_ALLOW_RUN_AS_ROOT=1" in res.stdout


def test_scenes_lists_where_they_live():
    res = run_cli(["scenes"])
    assert res.returncode == 0, res.stderr
    assert str(sc.scenes_dir()) in res.stdout and "mpipd scenes --show" in res.stdout


def test_show_prints_the_scene_and_its_file(tmp_path):
    res = run_cli(["scenes", "--show", "elastic_wave"])
    assert res.returncode == 0, res.stderr
    path = sc.builtin_scenes()["elastic_wave"]
    head, body = res.stdout.split("\n", 1)
    assert head == f"# built-in scene elastic_wave: {path}"
    assert path.is_file() and path.parent == sc.scenes_dir()
    assert body == path.read_text(encoding="utf-8-sig")
    copy = tmp_path / "mine.toml"                   # mpipd scenes --show NAME > mine.toml
    copy.write_text(res.stdout)
    assert sc.load(str(copy))[0] == sc.load("elastic_wave")[0]


def test_show_case_gives_the_overrides_that_make_the_case(tmp_path):
    res = run_cli(["scenes", "--show", "blast_demo:rockmass"])
    assert res.returncode == 0, res.stderr
    lines = res.stdout.splitlines()
    assert lines[0] == f"# built-in scene blast_demo: {sc.builtin_scenes()['blast_demo']}"
    assert str(sc.cases_dir() / "blast_demo.toml") in lines[1]
    assert sc.cases("blast_demo")["rockmass"].description in lines[1]
    sets = [shlex.split(ln[len("#   --set "):])[0] for ln in lines if ln.startswith("#   --set ")]
    assert sets == list(sc.cases("blast_demo")["rockmass"].set) and sets
    copy = tmp_path / "rockmass.toml"              # the copy plus the printed --set lines
    copy.write_text(res.stdout)
    mine = sc.load(str(copy), [*sets, 'scene.name="blast_demo-rockmass"'])[0]
    assert mine == sc.load("blast_demo:rockmass")[0]
    assert mine != sc.load("blast_demo")[0]


def test_show_refuses_what_is_not_built_in():
    one_error(run_cli(["scenes", "--show", "no_such_scene"]), "no built-in scene 'no_such_scene'",
              "blast_demo")
    one_error(run_cli(["scenes", "--show", "blast_demo:no_such_case"]),
              "no case 'no_such_case' of 'blast_demo'", "rockmass")


def test_error_key_pastes_back_into_set(tmp_path):
    """A key an error names (here in a file, the second part's dx) is the ``--set``
    spelling: passed back as ``--set KEY=VALUE`` it fixes that very value."""
    text = sc.builtin_scenes()["blast_demo"].read_text()
    bad = tmp_path / "bad.toml"
    bad.write_text(text.replace("dx = 3.0e-4", "dx = -3.0e-4"))      # the tube, parts.1
    line = one_error(run_cli(["check", str(bad)]), "must be > 0")
    key = line.removeprefix("mpipd: error: ").split(":", 1)[0]
    assert key == "parts.1.dx"
    res = run_cli(["check", str(bad), "--set", f"{key}=3.0e-4"])
    assert res.returncode == 0, res.stderr
    scene = sc.load(str(bad), [f"{key}=3.0e-4"])[0]
    assert scene == sc.load("blast_demo")[0]
