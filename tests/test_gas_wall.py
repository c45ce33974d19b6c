"""The gas wall (mpipd.materials.jwl.GasWall, mpipd.kernels.wall): a gas point held by
the interpolated surface of a solid, against closed forms on hand-built walls, and a
thrown charge held by a plate whose points are too far apart for the point contact."""
import h5py
import numpy as np
import pytest
from conftest import restart_matches, run_cli

from mpipd.input import scene as sc
from mpipd.kernels.ul import gas_gather
from mpipd.kernels.wall import DEPTH, EDGE, wall_gather, wall_update

KC = 2.0 * 7.3e10          # stiffness x rho0 vod^2 (Pa)
L_GAS, L_WALL, DELTA = 4.0e-4, 3.0e-4, 1.5e-3


def rotation(a, b, c):
    """A rotation matrix from three angles (rad)."""
    ca, sa, cb, sb, cc, sc_ = np.cos(a), np.sin(a), np.cos(b), np.sin(b), np.cos(c), np.sin(c)
    rx = np.array([[1, 0, 0], [0, ca, -sa], [0, sa, ca]])
    ry = np.array([[cb, 0, sb], [0, 1, 0], [-sb, 0, cb]])
    rz = np.array([[cc, -sc_, 0], [sc_, cc, 0], [0, 0, 1]])
    return rz @ ry @ rx


def plate(spacing, R, origin, n_side=7):
    """Wall points on a square lattice of ``spacing`` in the plane z = 0, rotated by R and
    moved to ``origin``; their reference normal R e_z (towards the gas, z > 0)."""
    k = np.arange(n_side) - (n_side - 1) / 2
    a, b = np.meshgrid(k * spacing, k * spacing, indexing="ij")
    pts = np.stack([a.ravel(), b.ravel(), np.zeros(a.size)], axis=1)
    return origin + pts @ R.T, np.tile(R @ np.array([0.0, 0.0, 1.0]), (len(pts), 1))


def scene_arrays(gas_at, spacing, R, origin=np.array([1e-3, -2e-3, 5e-4])):
    """Row 0: a gas point at plate coordinates ``gas_at`` (x, y along the plate, z its
    height over the points' plane); rows 1..: the plate.  Families: the gas point
    holds every plate point, each plate point the gas point."""
    wall, N = plate(spacing, R, origin)
    y = np.vstack([origin + R @ np.asarray(gas_at), wall])
    n = len(y)
    is_gas = np.zeros(n, np.uint8)
    is_gas[0] = 1
    is_wall = 1 - is_gas
    N_ref = np.vstack([np.zeros(3), N])
    l_wall = np.where(is_wall > 0, L_WALL, 0.0)
    offsets = np.concatenate([[0, n - 1], np.arange(n, 2 * n - 1)]).astype(np.int64)
    nbr = np.concatenate([np.arange(1, n), np.zeros(n - 1)]).astype(np.int32)
    delta = np.where(is_gas > 0, DELTA, 0.0)
    V = np.where(is_gas > 0, L_GAS ** 3, L_WALL ** 3)
    return dict(y=y, is_gas=is_gas, is_wall=is_wall.astype(np.uint8), N_ref=N_ref,
                l_wall=l_wall, offsets=offsets, nbr=nbr, delta=delta, V=V)


def wall_forces(a, g0, frac=0.5):
    """(force on every point in N, pushed count, depth) from wall_update + wall_gather."""
    n = len(a["y"])
    gw, gF = np.zeros((n, 3)), np.zeros((n, 3))
    on, depth = wall_update(np.array([0], np.int64), a["y"], a["offsets"], a["nbr"],
                            a["is_wall"], a["N_ref"], a["l_wall"], a["delta"],
                            np.array([L_GAS]), g0, gw, gF, frac, KC)
    f, fw = np.zeros((n, 3)), np.zeros((n, 3))
    wall_gather(np.arange(n, dtype=np.int64), a["y"], a["offsets"], a["nbr"], a["is_gas"],
                a["is_wall"], a["delta"], gw, gF, a["V"], f, fw)
    np.testing.assert_array_equal(f, fw)
    return f * a["V"][:, None], on, depth


@pytest.mark.parametrize("angles", [(0.0, 0.0, 0.0), (0.3, -1.1, 2.0)])
@pytest.mark.parametrize("spacing", [L_WALL, 1.0e-3])
def test_a_gas_point_against_a_flat_wall(angles, spacing):
    """A gas point over a flat plate (as laid, and stretched to 1 mm spacing), in any
    orientation: the gap to the face is its height less half the wall spacing,
    h = l_wall / 2; at the first check its standoff is g_0 = min(0.5 l_gas, g) (no force
    at rest); pressed to a height z the force is k l_gas (g_0 - g) along the plate's
    normal, and the plate points take it back in proportion to their weights
    (1 - r / delta)^2, summing to minus it."""
    R = rotation(*angles)
    normal = R @ np.array([0.0, 0.0, 1.0])
    # at rest 0.35 mm over the points' plane, above the middle of a lattice cell
    at = np.array([0.5 * spacing, 0.5 * spacing, 3.5e-4])
    g0 = np.full(1, np.nan)
    f, on, _ = wall_forces(scene_arrays(at, spacing, R), g0)
    assert on == 0 and not f.any()
    np.testing.assert_allclose(g0[0], min(0.5 * L_GAS, 3.5e-4 - 0.5 * L_WALL), rtol=1e-9)
    pressed = at - np.array([0.0, 0.0, 1.0e-4])
    a = scene_arrays(pressed, spacing, R)
    f, on, depth = wall_forces(a, g0)
    g = pressed[2] - 0.5 * L_WALL
    F = KC * L_GAS * (g0[0] - g)
    assert on == 1 and depth == pytest.approx((g0[0] - g) / L_GAS, rel=1e-9)
    np.testing.assert_allclose(f[0], F * normal, rtol=1e-9, atol=1e-9 * F)
    np.testing.assert_allclose(f[1:].sum(axis=0), -F * normal, rtol=1e-9, atol=1e-9 * F)
    r = np.linalg.norm(a["y"][1:] - a["y"][0], axis=1)
    w = np.clip(1.0 - r / DELTA, 0.0, None) ** 2
    np.testing.assert_allclose(np.linalg.norm(f[1:], axis=1), F * w / w.sum(), rtol=1e-9,
                               atol=1e-12 * F)


def test_the_stretched_plate_holds_where_the_point_contact_does_not():
    """studies/validation/notes.md §48: a plate stretched to 1 mm spacing, more than two
    point-contact reaches (0.9 l = 0.32 mm), and a gas point pressed through the middle
    of one of its cells: the point contact gives no force at all, the wall pushes it
    back along the normal."""
    spacing = 1.0e-3
    R = np.eye(3)
    at = np.array([0.5 * spacing, 0.5 * spacing, 3.5e-4])
    g0 = np.full(1, np.nan)
    wall_forces(scene_arrays(at, spacing, R), g0)
    through = at * np.array([1.0, 1.0, 0.0])            # in the points' own plane
    a = scene_arrays(through, spacing, R)
    f_wall, _, _ = wall_forces(a, g0)
    assert f_wall[0, 2] > 0.0 and abs(f_wall[0, 0]) < 1e-9 * f_wall[0, 2]
    n = len(a["y"])
    gd = np.zeros((n, 8))
    gd[:, 6] = a["V"]
    f = np.zeros((n, 3))
    gas_gather(np.arange(n, dtype=np.int64), a["y"], a["V"], a["V"].copy(), np.ones(n), gd,
               a["delta"], a["offsets"], a["nbr"], a["is_gas"], f, a["y"].copy(), 0.9, KC)
    assert not f.any()                                   # every pair beyond its reach


def test_no_force_beyond_the_wall_or_past_its_edge():
    """A gas point more than DEPTH spacings behind the face has passed the wall; one
    EDGE gas spacings beyond the plate's last row (out of an open end) is not over it:
    no force on either.  Over the last row the force is whole, and half way to EDGE it
    is half, along the plate's normal (the plane is the plate's)."""
    R = np.eye(3)
    half = 3 * L_WALL                                    # the 7 x 7 plate's half width
    g0 = np.full(1, 0.5 * L_GAS)
    behind = np.array([0.0, 0.0, 0.5 * L_WALL - (DEPTH + 0.1) * L_GAS])
    assert wall_forces(scene_arrays(behind, L_WALL, R), g0.copy())[1] == 0
    beyond = np.array([half + 0.25 * L_GAS + EDGE * L_GAS, 0.0, 2.0e-4])
    assert wall_forces(scene_arrays(beyond, L_WALL, R), g0.copy())[1] == 0
    partly = np.array([half + 0.5 * EDGE * L_GAS, 0.0, 2.0e-4])   # e = 1/2
    f_half = wall_forces(scene_arrays(partly, L_WALL, R), g0.copy())[0][0]
    over_edge = np.array([half, 0.0, 2.0e-4])
    f, on, _ = wall_forces(scene_arrays(over_edge, L_WALL, R), g0.copy())
    assert on == 1
    F = KC * L_GAS * (g0[0] - (2.0e-4 - 0.5 * L_WALL))
    np.testing.assert_allclose(f[0], [0.0, 0.0, F], rtol=1e-9, atol=1e-9 * F)
    np.testing.assert_allclose(f_half, [0.0, 0.0, 0.5 * F], rtol=1e-9, atol=1e-9 * F)


def test_a_wall_material_outside_interacts_with_is_refused():
    with pytest.raises(sc.SceneError, match="interacts_with"):
        sc.load("detonation_tube", ['materials.explosive.wall={ material = "granite" }'])
    with pytest.raises(sc.SceneError, match="distance"):
        sc.load("detonation_tube", ['materials.explosive.wall={ material = "copper", '
                                    'distance = 1.5 }'])


#: an unlit charge thrown (+x at 1 km/s, sliding along z at 300 m/s) at a copper plate
#: 1 mm away whose lattice is 1 mm: wider than two point-contact reaches
THROWN = """
[scene]
name = "wall_impact"
[time]
dt = 1.5e-8
t_end = 1.8e-6
[materials.explosive]
model = "jwl"
damping = 0.0
interacts_with = ["copper"]
wall = { material = "copper" }
[materials.copper]
model = "j2"
[[parts]]
name = "charge"
material = "explosive"
dx = 5.0e-4
shape = { kind = "box", lo = [-0.002, -0.002, 0.0], hi = [0.0, 0.002, 0.006] }
initiation = { never = true }
[[parts]]
name = "plate"
material = "copper"
dx = 1.0e-3
horizon_factor = 2.0
shape = { kind = "box", lo = [0.0005, -0.003, -0.001], hi = [0.0035, 0.003, 0.007] }
[[initial]]
kind = "uniform_velocity"
region = { lo = [-0.002, -0.002, 0.0], hi = [0.0, 0.002, 0.006] }
velocity = [1000.0, 0.0, 300.0]
[output]
every = 10
fields = ["u", "v"]
"""


def test_the_wall_holds_a_thrown_charge_on_any_rank_count(tmp_path):
    """Without the wall the charge passes into the coarse plate; with it no gas point
    passes the plate's face layer at any frame, the ledger closes with the wall's work
    booked (gas_wall > 0 during the impact), and u and v are bit-identical on 1, 2 and
    3 ranks and after a restart on 3 ranks of a run stopped on 2."""
    path, path_off = tmp_path / "thrown.toml", tmp_path / "off.toml"
    path.write_text(THROWN)
    path_off.write_text(THROWN.replace('wall = { material = "copper" }\n', ""))
    out = {}
    for n in (1, 2, 3, "off"):
        res = run_cli(["run", str(path_off if n == "off" else path), "--out",
                       str(tmp_path / f"n{n}"), "--quiet"],
                      ranks=n if isinstance(n, int) else 1, timeout=300)
        assert res.returncode == 0, res.stdout + res.stderr
        out[n] = tmp_path / f"n{n}" / "run.h5"

    def gas_and_face(f):
        mat = f["geometry/material"][...]
        x = f["geometry/x"][...]
        y = x[None] + f["fields/u"][...]
        face = (mat == 1) & (x[:, 0] < 1.5e-3)              # the plate's first layer
        return y[:, mat == 0, 0], y[:, face, 0]

    with h5py.File(out["off"], "r") as f:
        gx, px = gas_and_face(f)
        assert gx[-1].max() > px[-1].min() + 2.0e-4          # passed into the plate
    with h5py.File(out[1], "r") as f:
        gx, px = gas_and_face(f)
        assert np.all(gx.max(axis=1) < px.min(axis=1))       # never past its face layer
        en = f["energy"]
        assert en["gas_wall"][...].max() > 1e-3 * en["initial"][0]
        assert np.abs(en["balance"][...]).max() < 1e-3
        ref = {k: f[k][...] for k in ("fields/u", "fields/v")}
    for n in (2, 3):
        with h5py.File(out[n], "r") as f:
            for k, a in ref.items():
                assert np.array_equal(f[k][...], a), f"{k} differs between 1 and {n} ranks"
    d = tmp_path / "r"
    res = run_cli(["run", str(path), "--out", str(d), "--quiet", "--stop-after", "60"],
                  ranks=2, timeout=300)
    assert res.returncode == 0, res.stdout + res.stderr
    done = restart_matches(d / "checkpoint.h5", out[1], ("fields/u", "fields/v"), ranks=3)
    with h5py.File(done, "r") as f, h5py.File(out[1], "r") as g:
        np.testing.assert_allclose(f["energy/gas_wall"][...], g["energy/gas_wall"][...],
                                   rtol=1e-9, atol=1e-12 * float(g["energy/initial"][0]))
