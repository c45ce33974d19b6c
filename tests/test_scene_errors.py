"""Bad input: one clear line naming what is wrong, exit status 2, nothing written."""
import pytest
from conftest import check_bad, run_cli

from mpipd.input import scene as sc

CASES = [
    (["--set", "parts.0.radus=1"], "parts.0.radus", "unknown key"),
    (["--set", 'parts.0.dx="abc"'], "parts.0.dx", "expected a number"),
    (["--set", "parts.0.dx=-0.001"], "parts.0.dx", "must be > 0"),
    (["--set", "parts.0.horizon_factor=0.5"], "parts.0.horizon_factor", "at least dx"),
    (["--set", 'parts.0.influence="cubic"'], "parts.0.influence", "unknown influence function"),
    (["--set", "time.steps=-1"], "time.steps", "must be >= 0"),
    (["--set", "materials.granite.model=rubber"], "materials.granite.model", "unknown material"),
    (["--set", "parts.0.material=basalt"], "parts.0.material", "no material"),
    (["--set", "output.fields=[\"u\",\"temperature\"]"], "output.fields.1", "unknown field"),
    (["--set", "initial.0.axis=w"], "initial.0.axis", "must be one of"),
    (["--set", "time.dt=true"], "time.dt", "expected a number"),
]


@pytest.mark.parametrize("args,key,reason", CASES)
def test_bad_override(tmp_path, args, key, reason):
    out = tmp_path / "out"
    res = run_cli(["run", "elastic_wave", "--out", str(out), *args])
    check_bad(res, out, key, reason)


def test_missing_value(tmp_path):
    text = sc.builtin_scenes()["elastic_wave"].read_text().replace("dx = 1.0e-3\n", "")
    f = tmp_path / "s.toml"
    f.write_text(text)
    out = tmp_path / "out"
    check_bad(run_cli(["run", str(f), "--out", str(out)]), out, "parts.0.dx", "missing value")


def test_not_toml(tmp_path):
    f = tmp_path / "s.toml"
    f.write_text("this is [not toml\n")
    out = tmp_path / "out"
    check_bad(run_cli(["run", str(f), "--out", str(out)]), out, str(f), "not a valid TOML")


def test_unknown_scene(tmp_path):
    out = tmp_path / "out"
    check_bad(run_cli(["run", "no_such_scene", "--out", str(out)]), out, "no_such_scene",
              "elastic_wave")


def test_check_reports_bad_scene_too(tmp_path):
    res = run_cli(["check", "elastic_wave", "--set", "parts.0.dx=-1"])
    assert res.returncode == 2 and "parts.0.dx: must be > 0" in res.stderr


def test_existing_output_is_not_overwritten(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    (out / "run.h5").write_bytes(b"precious")
    res = run_cli(["run", "elastic_wave", "--out", str(out)])
    assert res.returncode == 2 and "exists" in res.stderr and "--overwrite" in res.stderr
    assert (out / "run.h5").read_bytes() == b"precious"


def test_bad_scene_under_mpirun_one_message(tmp_path):
    out = tmp_path / "out"
    res = run_cli(["run", "elastic_wave", "--out", str(out), "--set", "parts.0.dx=0"],
                  ranks=2, timeout=120)
    check_bad(res, out, "parts.0.dx", "must be > 0", mpirun=True)


GEOMETRY_CASES = [
    (["--set", "time.dt=inf"], "time.dt", "finite"),
    (["--set", "parts.0.dx=nan"], "parts.0.dx", "finite"),
    (["--set", "parts.0.shape.lo=[0,0,nan]"], "parts.0.shape.lo.2", "finite"),
    (["--set", "parts.0.dx=1e-9"], "parts.0.dx", "too small"),
    (["--set", 'parts.0.shape={kind="cylinder", center=[0,0], radius=1e-4, z=[0,0.01]}'],
     "parts.0.shape", "no lattice point"),
]


@pytest.mark.parametrize("args,key,reason", GEOMETRY_CASES)
def test_bad_numbers_and_geometry(tmp_path, args, key, reason):
    out = tmp_path / "out"
    check_bad(run_cli(["run", "elastic_wave", "--out", str(out), *args]), out, key, reason)
    res = run_cli(["check", "elastic_wave", *args])
    assert res.returncode == 2 and key in res.stderr


def test_overlapping_parts(tmp_path):
    text = sc.builtin_scenes()["elastic_wave"].read_text()
    text += ('\n[[parts]]\nname = "bar2"\nmaterial = "granite"\ndx = 1.0e-3\n'
             'shape = { kind = "box", lo = [0.1, 0.0, 0.0], hi = [0.3, 0.016, 0.016] }\n')
    f = tmp_path / "s.toml"
    f.write_text(text)
    out = tmp_path / "out"
    check_bad(run_cli(["run", str(f), "--out", str(out)]), out, "overlaps")


def test_an_optional_table_is_switched_off_by_false():
    """TOML has no null: ``false`` switches an optional table (X | None) off, so a
    named case can take back a base scene's option (``contact=false``), while
    ``true`` or a number there is still an error naming the key."""
    from mpipd.input.scene import load
    from mpipd.input.schema import SceneError
    on = load("blast_demo", ["materials.explosive.contact={ distance = 0.9 }"])[0]
    assert on.materials["explosive"].contact is not None
    off = load("blast_demo", ["materials.explosive.contact={ distance = 0.9 }",
                              "materials.explosive.contact=false"])[0]
    assert off.materials["explosive"].contact is None
    for bad in ("true", "1.0"):
        with pytest.raises(SceneError, match="materials.explosive.contact"):
            load("blast_demo", [f"materials.explosive.contact={bad}"])
