"""The report of any scene (mpipd/post/scene_report.py) and the warnings a user cannot
miss (mpipd/post/alerts.py) on tiny runs of a box of granite with one borehole and no
tube, and with two holes; the paper's specimen is recognised from the scene alone.

The scenes: a box 40 x 40 x 4 mm (two holes: 48 x 40 x 4 mm), rock at dx 2 mm, charges
at 0.8 mm, 100 steps of 0.04 us, a frame every 25 steps."""
import json

import pytest
from conftest import run_cli

from mpipd.post import alerts
from mpipd.post.charges import NAMES

#: two scenes run and reported (about 100 s): the long tier (make stability), to keep
#: make test under its 20 minutes
pytestmark = pytest.mark.long

BOX = """
[scene]
name = "{name}"
description = "test: charges in holes of a granite box, no tube"

[time]
dt = 4.0e-8
t_end = 4.0e-6

[materials.explosive]
model = "jwl"
interacts_with = ["granite"]
contact = {{ distance = 0.9, stiffness = 1.0 }}

[materials.granite]
model = "jh2"
pressure = "incremental"
tension = {{ sigma_st = -6.9e6, c1 = 0.33, rate0 = 0.4 }}
{charges}
[[parts]]
name = "rock"
material = "granite"
dx = 2.0e-3
horizon_factor = 3.0
shape = {{ kind = "box", lo = [{x0}, -0.02, 0.0], hi = [{x1}, 0.02, 0.004], holes = [{holes}] }}

[solver]
hourglass = 0.01
contact = true
damping = 2.0e5
viscosity = {{ cq = 8.0, cl = 0.1 }}

[output]
every = 25
fields = ["u", "v", "damage", "failure_mode", "pressure", "peak_pressure", "peak_speed", "gas_force"]

[[probes]]
name = "R5"
position = [0.0085, 0.0005, 0.001]
part = "rock"
"""

CHARGE = """
[[parts]]
name = "{name}"
material = "explosive"
dx = 8.0e-4
horizon_factor = 3.0
shape = {{ kind = "cylinder", center = [{cx}, 0.0], radius = 0.0032, z = [0.0, 0.004] }}
initiation = {{ z = 0.0, time = 0.0 }}
"""


def scene(name, centers, x0, x1):
    charges = "".join(CHARGE.format(name=f"hole{i + 1}", cx=c) for i, c in enumerate(centers))
    holes = ", ".join(f"{{ center = [{c}, 0.0], radius = 0.0032 }}" for c in centers)
    return BOX.format(name=name, charges=charges, holes=holes, x0=x0, x1=x1)


def made(tmp_path_factory, name, centers, x0, x1):
    d = tmp_path_factory.mktemp(name)
    (d / "scene.toml").write_text(scene(name, centers, x0, x1))
    res = run_cli(["run", str(d / "scene.toml"), "--quiet", "--out", str(d / "run")], timeout=600)
    assert res.returncode == 0, res.stdout + res.stderr
    return d / "run", res.stdout + res.stderr


@pytest.fixture(scope="module")
def one_hole(tmp_path_factory):
    return made(tmp_path_factory, "one_hole", [0.0], -0.02, 0.02)


@pytest.fixture(scope="module")
def two_holes(tmp_path_factory):
    return made(tmp_path_factory, "two_holes", [-0.01, 0.01], -0.024, 0.024)


def report(run_dir, *extra):
    import subprocess
    import sys

    from conftest import child_env
    out = run_dir / ("report" + "".join(extra).replace("-", "_"))
    res = subprocess.run([sys.executable, "-m", "mpipd.post", "report", str(run_dir / "run.h5"),
                          "--out", str(out), *extra], capture_output=True, text=True,
                         timeout=300, env=child_env())
    assert res.returncode == 0, res.stderr
    return json.loads((out / "report.json").read_text()), (out / "report.md").read_text(), out


PAPER_ONLY = ("tube", "Banadaki", "Fig. 11", "R_o", "outer radius", "DESIGN", "issue ")


def test_one_hole_report_is_the_scenes(one_hole):
    doc, md, out = report(one_hole[0])
    assert doc["paper"]["applied"] is False
    assert "annulus" in doc["paper"]["reason"]
    for word in PAPER_ONLY:
        assert word not in md, word
    assert "targets" not in doc
    assert all(not e["message"].count("tube") for e in doc["errors"])
    # sections through the rock, named, at the rock's own levels (dx 2 mm: 1 and 3 mm)
    assert set(doc["sections_mm"]) <= set(NAMES) and doc["sections_mm"]
    assert sorted(round(v, 6) for v in doc["sections_mm"].values()) == [1.0, 3.0]
    per = doc["per_charge"][NAMES[1]]["hole1"]
    assert per["points"] > 0 and per["failed_points"] > 0
    assert per["damaged_extent_mm"] > 3.2            # beyond the hole's wall
    assert per["r_free_mm"] == pytest.approx(20.0)    # the box's half-width
    assert {"boundary", "gas_wall"} <= set(doc["energy_ledger"]["final_J"])
    for fig in ("damage_sections", "failure_modes", "energy_ledger", "probes"):
        assert (out / doc["figures"][fig]).is_file()


def test_one_hole_warns_the_gas_leaves_its_hole(one_hole):
    run_dir, log = one_hole
    doc, md, _ = report(run_dir)
    kinds = {w["kind"] for w in doc["warnings"]}
    assert "gas leaves its hole" in kinds
    leave = next(w for w in doc["warnings"] if w["kind"] == "gas leaves its hole")
    assert 'materials.explosive.wall = { material = "granite" }' in leave["fix"]
    assert "## Warnings" in md and "gas leaves its hole" in md
    # the run's own summary ends with the same block
    assert "WARNING:" in log and "gas leaves its hole" in log


def test_two_holes_measures_each_charge(two_holes):
    doc, md, _ = report(two_holes[0])
    assert doc["paper"]["applied"] is False
    per = doc["per_charge"][NAMES[1]]
    assert set(per) == {"hole1", "hole2"}
    for c in per.values():
        # half the distance between the holes (20 mm) bounds each charge's room
        assert c["r_free_mm"] == pytest.approx(10.0)
        assert c["damaged_extent_mm"] is None or c["damaged_extent_mm"] <= 14.2
    assert "Borehole wall R_b" not in md and "borehole radii" not in md
    assert not any("intact rock" in e["message"] and "tube" in e["message"]
                   for e in doc["errors"])


def test_paper_option_forces_the_validation_layer(one_hole):
    doc, md, _ = report(one_hole[0], "--paper")
    assert doc["paper"]["applied"] is True and "not:" in doc["paper"]["reason"]
    assert "targets" in doc
    # no tube in the scene: no error may name one
    assert not any("tube" in e["message"] for e in doc["errors"])


def test_warnings_quiet_on_a_run_that_should_not_fire(two_holes, one_hole):
    """The thresholds, on measures that fire and on ones that do not."""
    quiet = {"a4": 0.1, "noise": 0.01, "n_failed": 300}
    loud = {"a4": 0.6, "noise": 0.05, "n_failed": 300}
    noisy = {"a4": 0.4, "noise": 0.2, "n_failed": 20}
    from mpipd.post.model import load_model
    from mpipd.post.reader import Run
    run = Run(str(one_hole[0] / "run.h5"))
    try:
        model = load_model(run)
        assert alerts.lattice(run, model, {"mid": {"hole1": quiet}}) == []
        assert alerts.lattice(run, model, {"mid": {"hole1": noisy}}) == []
        got = alerts.lattice(run, model, {"mid": {"hole1": loud}})
        assert len(got) == 1 and "parts.1.jitter" in got[0]["fix"] \
            and "materials.granite.heterogeneity" in got[0]["fix"]
        assert alerts.pressure(run, model) == []          # 17 GPa < 1.5 x 15.5 GPa
        model.charges[0]["p_CJ"] = 5e9                    # a charge whose p_CJ it exceeds
        assert [w["kind"] for w in alerts.pressure(run, model)] == ["gas pressure"]
    finally:
        run.close()


def test_fracture_shows_the_rock_and_refuses_a_section_without_it(one_hole, tmp_path):
    h5 = str(one_hole[0] / "run.h5")
    import subprocess
    import sys

    from conftest import child_env

    def post(*a):
        return subprocess.run([sys.executable, "-m", "mpipd.post", *a], capture_output=True,
                              text=True, timeout=300, env=child_env())
    ok = post("fracture", h5, "--out", str(tmp_path / "f.png"))
    assert ok.returncode == 0 and "part 'rock'" in ok.stdout and "1 mm" in ok.stdout
    bad = post("fracture", h5, "--z", "0.002", "--out", str(tmp_path / "g.png"))
    assert bad.returncode == 2 and len(bad.stderr.strip().splitlines()) == 1
    assert "holds no point of part 'rock'" in bad.stderr
    gif = post("animate", h5, "--out", str(tmp_path / "d.gif"))
    assert gif.returncode == 0, gif.stderr
    from PIL import Image
    im = Image.open(tmp_path / "d.gif")
    assert im.n_frames == 5
