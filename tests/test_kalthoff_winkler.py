"""Kalthoff-Winkler (the built-in scene kalthoff_winkler): the crack-angle measure
(mpipd.post.crack_angle) on hand-built cracks, the scene's notches, a coarse short run
on 1, 2 and 3 ranks (bit-identical fields, the ledger closed with its ``boundary``
term), and (``long``) the full scene against the experiment's crack angle."""
import math

import h5py
import numpy as np
import pytest
from conftest import run_cli

from mpipd.input import scene as sc
from mpipd.model.ledger import BALANCE_TOL
from mpipd.post.crack_angle import Notch, crack_angle, edge_notches, measure, mid_plane

#: the coarse short run: dx 3 mm (3 levels through the 9 mm), the driven layer and the
#: crack band's strength sqrt(2 E G0 / dx) at that dx (benchmarks/problems/kalthoff_winkler),
#: to 60 us (the first cracks leave the tips at ~40 us at this dx)
COARSE = ["parts.0.dx=3e-3", "boundaries.0.region.hi=[3e-3, 0.025, 0.009]",
          f"materials.steel.tension.sigma_st={-math.sqrt(2 * 190e9 * 22170 / 3e-3)!r}",
          "time.t_end=6e-5", "output.every=100"]


def ray(tip, angle_deg, side, n=30, spacing=7.5e-4, lo=0.0, hi=0.03):
    """Points on a ray from ``tip`` at ``angle_deg`` to +x, turning to +y (side 1) or -y."""
    a = math.radians(angle_deg)
    s = np.linspace(lo, hi, n)
    return np.column_stack([tip[0] + s * math.cos(a), tip[1] + side * s * math.sin(a)])


def test_a_straight_crack_gives_its_angle_on_either_side():
    tip = (0.05, 0.025)
    for ang, side in ((70.0, 1), (70.0, -1), (35.0, 1), (85.0, -1)):
        xy = ray(tip, ang, side)
        got = crack_angle(xy, np.ones(len(xy), bool), Notch(tip, (1.0, 0.0)))
        assert got.angle_deg == pytest.approx(ang, abs=1e-9)
        assert got.side == side
        assert got.spread < 1e-12                      # one line through the tip


def test_the_window_and_the_damage_mask_select_the_points():
    """Only damaged points 5-25 mm from the tip and not behind it count: a second crack
    beyond the window, undamaged points on a third line and the notch's own faces
    behind the tip do not move the angle."""
    tip = (0.05, 0.025)
    main = ray(tip, 68.0, 1)
    far = ray(tip, 10.0, 1, lo=0.03, hi=0.06)            # beyond r_max
    clean = ray(tip, 20.0, -1)                           # not damaged
    notch = np.column_stack([np.linspace(0.0, 0.05, 30), np.full(30, 0.025)])   # behind
    xy = np.vstack([main, far, clean, notch])
    grown = np.r_[np.ones(len(main) + len(far), bool), np.zeros(len(clean), bool),
                  np.ones(len(notch), bool)]
    got = crack_angle(xy, grown, Notch(tip, (1.0, 0.0)))
    assert got.angle_deg == pytest.approx(68.0, abs=1e-9)
    inside = np.hypot(*(main - tip).T)
    assert got.points == np.count_nonzero((inside >= 0.005) & (inside <= 0.025))


def test_no_damaged_point_gives_nan():
    got = crack_angle(np.zeros((3, 2)), np.zeros(3, bool), Notch((0.05, 0.025), (1.0, 0.0)))
    assert math.isnan(got.angle_deg) and got.points == 0


def test_the_scene_has_two_edge_notches_50_mm_deep_50_mm_apart():
    scene, _ = sc.load("kalthoff_winkler")
    q = scene.parts[0]
    x = np.array([[q.shape.lo[0] + q.dx / 2, q.shape.lo[1] + q.dx / 2, 0.0],
                  [q.shape.hi[0] - q.dx / 2, q.shape.hi[1] - q.dx / 2, 0.009]])
    notches = edge_notches(scene.joints, x)
    assert [n.tip for n in notches] == [(0.05, -0.025), (0.05, 0.025)]
    assert all(n.direction == (1.0, 0.0) for n in notches)
    assert mid_plane(np.array([0.75, 2.25, 3.75, 5.25, 6.75, 8.25])).tolist() == \
        [False, False, True, True, False, False]


@pytest.fixture(scope="module")
def coarse(tmp_path_factory):
    """The coarse short run on 1, 2 and 3 ranks."""
    out = {}
    for ranks in (1, 2, 3):
        folder = tmp_path_factory.mktemp("kw") / f"r{ranks}"
        args = ["run", "kalthoff_winkler", "--out", str(folder), "--quiet"]
        for o in COARSE:
            args += ["--set", o]
        res = run_cli(args, ranks=ranks if ranks > 1 else None, timeout=600)
        assert res.returncode == 0, res.stdout[-2000:] + res.stderr[-2000:]
        out[ranks] = folder / "run.h5"
    return out


@pytest.mark.long      # three 60 us runs: make stability, to keep make test under 20 min
def test_one_two_and_three_ranks_are_bit_identical(coarse):
    with h5py.File(coarse[1], "r") as f1:
        ref = {k: f1["fields"][k][:] for k in ("u", "v", "damage")}
        assert ref["damage"][-1].max() == 1.0               # something broke
        for ranks in (2, 3):
            with h5py.File(coarse[ranks], "r") as f:
                for k, a in ref.items():
                    np.testing.assert_array_equal(f["fields"][k][:], a, err_msg=f"{k}, {ranks}")


@pytest.mark.long      # three 60 us runs: make stability, to keep make test under 20 min
def test_the_ledger_closes_with_the_boundary_work(coarse):
    """Every frame's |balance| within the ledger's own bound (BALANCE_TOL); the boundary
    term holds the energy the plate received (initial 0)."""
    with h5py.File(coarse[2], "r") as f:
        b = f["energy/balance"][:]
        work, held, diss = (f["energy/boundary"][-1], f["energy/kinetic"][-1],
                            f["energy/removed"][-1])
        initial = f["energy/initial"][-1]
    assert np.all(np.abs(b) < BALANCE_TOL), b
    assert abs(initial) < 1e-20 and work > 0 and held > 0 and diss > 0


@pytest.mark.long      # three 60 us runs: make stability, to keep make test under 20 min
def test_the_coarse_cracks_leave_both_tips_forward(coarse):
    """At 3 mm and 60 us both tips have cracked, forward and outward (0-90 deg, away
    from the mid-line).  The angle itself is the long test's, at 1.5 mm."""
    out = measure(coarse[1])
    for a in out["notches"]:
        assert a["points"] >= 2, a
        assert 0.0 < a["angle_deg"] < 90.0
        assert a["side"] == (1.0 if a["tip"][1] > 0 else -1.0)


@pytest.fixture(scope="module")
def full(tmp_path_factory):
    folder = tmp_path_factory.mktemp("kw_full")
    res = run_cli(["run", "kalthoff_winkler", "--out", str(folder), "--quiet"], ranks=2,
                  timeout=1800)
    assert res.returncode == 0, res.stdout[-2000:] + res.stderr[-2000:]
    return folder / "run.h5"


@pytest.mark.long
def test_the_full_scene_closes_its_ledger(full):
    with h5py.File(full, "r") as f:
        b = f["energy/balance"][:]
        assert f["energy/boundary"][-1] > 0
    assert np.all(np.abs(b) < BALANCE_TOL), b           # measured 1.2e-5 at 90 us


@pytest.mark.long
@pytest.mark.xfail(strict=True, reason="measured at dx 1.5 mm, 90 us (2 ranks): 60.2 deg at "
                   "the tip y = -25 mm, 53.4 deg at y = +25 mm, 6.8 deg apart; the -25 mm crack "
                   "arrests after ~10 mm while the other runs to the far edge (CHANGELOG, "
                   "docs/examples.md)")
def test_the_cracks_leave_the_notches_at_60_to_75_degrees_symmetric(full):
    out = measure(full)
    angles = [a["angle_deg"] for a in out["notches"]]
    assert all(60.0 <= a <= 75.0 for a in angles), angles
    assert abs(angles[0] - angles[1]) <= 5.0, angles
