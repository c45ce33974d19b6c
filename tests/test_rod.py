"""Charges, tubes and holes along any axis (issue 19): the ``rod`` shape, a box's hole
along an axis other than z, and a charge lit from a point."""
import subprocess
import sys

import h5py
import numpy as np
import pytest
from conftest import check_bad, child_env, restart_matches, run_cli

from mpipd.input import scene as sc
from mpipd.input.geometry import Annulus, Box, Cylinder, Hole, Rod, part_points
from mpipd.model.gas import lighting_times

DX = 4.0e-4


def sites(shape, dx=DX):
    """Every lattice site of a shape, (n, 3), from its sections level by level."""
    out = []
    for z in shape.z_levels(dx):
        x, y = shape.section(dx, z)
        out.append(np.column_stack((x, y, np.full(len(x), z))))
    return np.concatenate(out)


def ordered(p):
    """The rows of p sorted (x, then y, then z)."""
    return p[np.lexsort(p.T[::-1])]


def as_set(p):
    return {tuple(v) for v in np.round(p * 1e9).astype(np.int64)}


@pytest.mark.parametrize("axis", [0, 1])
def test_a_rod_along_an_axis_is_the_cylinder_turned_onto_it(axis):
    """A rod along x (or y) holds the sites of the z cylinder of the same radius and
    length with z swapped for that axis, exactly: same offsets, same inequalities."""
    c0, c1, zc, r, L = 0.0013, -0.0007, 0.0021, 0.0016, 0.0060
    for cyl, inner in ((Cylinder(center=(c0, c1), radius=r, z=(zc, zc + L)), 0.0),
                       (Annulus(center=(c0, c1), radius=r, z=(zc, zc + L), inner_radius=0.0010), 0.0010)):
        perm = [0, 1, 2]
        perm[axis], perm[2] = 2, axis            # swap z with the rod's axis
        start = np.array([c0, c1, zc])[perm]
        end = start.copy()
        end[axis] += L
        rod = Rod(start=tuple(start), end=tuple(end), radius=r, inner_radius=inner)
        x, y = cyl.cross_section(DX)
        z = cyl.z_levels(DX)
        ref = np.column_stack((np.tile(x, len(z)), np.tile(y, len(z)), np.repeat(z, len(x))))
        got = sites(rod)
        assert len(got) == len(ref)
        np.testing.assert_array_equal(ordered(got[:, perm]), ordered(ref))


def dist_to_line(p, a, b):
    """Distance from points p to the line through a and b, and the axial coordinate
    (from a, along a->b), by the cross product: |(p - a) x u|."""
    u = (np.asarray(b) - a) / np.linalg.norm(np.asarray(b) - a)
    d = p - a
    return np.linalg.norm(np.cross(d, u), axis=1), d @ u


def test_a_tilted_rod_fills_its_cylinder():
    """A rod along (1, 2, 2)/3 holds exactly the lattice sites start + (i + 1/2) dx
    within its radius and between its end planes (brute force over its bounding
    box), and their volume is its volume pi r^2 L to within the lattice's error."""
    a = np.array([0.001, -0.002, 0.0005])
    L, r = 0.0091, 0.00151              # no site on the surface: no ties to round
    b = a + L * np.array([1.0, 2.0, 2.0]) / 3.0
    rod = Rod(start=tuple(a), end=tuple(b), radius=r)
    got = sites(rod)
    k = np.arange(-12, 40) + 0.5
    grid = a + DX * np.stack(np.meshgrid(k, k, k, indexing="ij"), -1).reshape(-1, 3)
    d, s = dist_to_line(grid, a, b)
    ref = grid[(d <= r) & (s >= 0.0) & (s <= L)]
    assert as_set(got) == as_set(ref)
    assert len(got) * DX ** 3 == pytest.approx(np.pi * r * r * L, rel=0.05)    # r = 3.8 dx


def test_a_box_hole_along_an_axis_removes_the_sites_within_its_radius():
    """A hole from start to end along (2, 0, 1)/sqrt(5) through a box removes the
    box's sites within its radius of the axis between its end planes, no more."""
    box0 = Box(lo=(0.0, 0.0, 0.0), hi=(0.012, 0.006, 0.008))
    a, b, r = np.array([-0.001, 0.003, 0.001]), np.array([0.011, 0.003, 0.007]), 0.00151
    box = Box(lo=box0.lo, hi=box0.hi, holes=(Hole(start=tuple(a), end=tuple(b), radius=r),))
    assert not box.prism and box0.prism
    full = sites(box0, 5e-4)
    d, s = dist_to_line(full, a, b)
    L = np.linalg.norm(b - a)
    inside = (d <= r) & (s >= 0) & (s <= L)
    assert 100 < inside.sum() < len(full)
    assert as_set(sites(box, 5e-4)) == as_set(full[~inside])
    p = full[~inside]
    assert np.all(box.contains(p[:, 0], p[:, 1], p[:, 2], -1e-12))
    q = full[(d < 0.9 * r) & (s > 0.1 * L) & (s < 0.9 * L)]
    assert not np.any(box.contains(q[:, 0], q[:, 1], q[:, 2], 0.0))


def test_a_charge_lit_from_a_point_burns_outward_at_the_vod():
    """initiation = { point } lights x at time + |x - point| / vod."""
    scene, _ = sc.load("blast_bench", ["parts.2.initiation={ point = [0.0, 0.015, 0.003], "
                                       "time = 5e-6 }"])
    mat = scene.materials["explosive"]
    x = np.array([[0.0, 0.015, 0.003], [0.001, 0.015, 0.003], [0.0, 0.017, 0.0], [0, 0, 0.0]])
    part = np.array([2, 2, 2, 0])
    t = lighting_times(scene, part, x, mat)
    expect = 5e-6 + np.array([0.0, 0.001, np.hypot(0.002, 0.003)]) / mat.vod
    np.testing.assert_allclose(t[:3], expect, rtol=0, atol=1e-18)
    assert t[3] == 0.0                                  # charge1 keeps its face at z = 0


BAD = [
    ('parts.0.shape={ kind = "rod", start = [0, 0, 0], end = [0, 0, 0], radius = 1e-3 }',
     "parts.0.shape.end", "must differ from start"),
    ('parts.0.shape={ kind = "rod", start = [0, 0, 0], end = [0.01, 0, 0], radius = 1e-3, '
     'inner_radius = 1e-3 }', "parts.0.shape.inner_radius", "[0, radius)"),
    ("parts.6.shape.holes.0={ center = [0.0, 0.015], start = [0, 0, 0], radius = 1e-3 }",
     "parts.6.shape.holes.0", "either center"),
    ("parts.6.shape.holes.0={ start = [0, 0, 0], radius = 1e-3 }",
     "parts.6.shape.holes.0", "both start and end"),
    ("parts.0.initiation={ point = [0, 0, 0], z = 0.003 }",
     "parts.0.initiation.point", "not both"),
]


@pytest.mark.parametrize("setting,key,reason", BAD)
def test_bad_rods_holes_and_initiations(tmp_path, setting, key, reason):
    out = tmp_path / "out"
    check_bad(run_cli(["run", "blast_bench", "--out", str(out), "--set", setting]), out,
              key, reason)


def test_a_borehole_pressure_refuses_a_part_along_another_axis(tmp_path):
    f = tmp_path / "s.toml"
    f.write_text(SCENE.format(o="x", **AXES["x"]).replace(
        '[materials.explosive]\nmodel = "jwl"\ninteracts_with = ["granite"]\n', "").replace(
        'name = "charge"\nmaterial = "explosive"', 'name = "charge"\nmaterial = "granite"')
        .replace('initiation = { point = [0.0, 0.0, 0.0], time = 0.0 }\n', "")
        + '\n[[loads]]\nkind = "borehole_pressure"\ncenter = [0.0, 0.0]\nradius = 0.002\n'
          'p0 = 1e9\nalpha = 1e5\nbeta = 1e6\n')
    out = tmp_path / "out"
    check_bad(run_cli(["run", str(f), "--out", str(out)]), out, "loads.0", "prisms along z")


# A charge in a hole through a granite block, lit from a point at one end: along z, and
# the same scene with x and z swapped (a charge along x, across the slabs).
SCENE = """
[scene]
name = "rod_{o}"

[time]
dt = 2.0e-8
t_end = 3.0e-6

[materials.explosive]
model = "jwl"
interacts_with = ["granite"]

[materials.granite]
model = "jh2"
tension = {{ sigma_st = -6.9e6, c1 = 0.33, rate0 = 0.4 }}

[[parts]]
name = "charge"
material = "explosive"
dx = 5.0e-4
horizon_factor = 3.75
shape = {charge}
initiation = {{ point = [0.0, 0.0, 0.0], time = 0.0 }}

[[parts]]
name = "rock"
material = "granite"
dx = 1.0e-3
shape = {rock}

[solver]
hourglass = 0.01
viscosity = {{ cq = 8.0, cl = 0.1 }}

[output]
every = 30
checkpoint_every = 60
fields = ["u", "v", "damage"]
"""
AXES = {
    "z": dict(charge='{ kind = "cylinder", center = [0.0, 0.0], radius = 0.002, z = [0.0, 0.012] }',
              rock='{ kind = "box", lo = [-0.006, -0.006, 0.0], hi = [0.006, 0.006, 0.012], '
                   'holes = [{ center = [0.0, 0.0], radius = 0.002 }] }'),
    "x": dict(charge='{ kind = "rod", start = [0.0, 0.0, 0.0], end = [0.012, 0.0, 0.0], '
                     'radius = 0.002 }',
              rock='{ kind = "box", lo = [0.0, -0.006, -0.006], hi = [0.012, 0.006, 0.006], '
                   'holes = [{ start = [-0.001, 0.0, 0.0], end = [0.013, 0.0, 0.0], '
                   'radius = 0.002 }] }'),
}


def test_a_charge_along_x_gives_the_z_charges_answer_mirrored(tmp_path):
    """The same blast with x and z swapped (a mirror: the lattice, the hole, the charge
    and its point of initiation map onto each other site for site) gives the same
    displacements, swapped, to round-off: the charge along x lies across the slabs
    (2 and 3 ranks), the z one along them (1 rank); the charge along x is bit-identical
    on 2 and 3 ranks and after a restart from 2 ranks onto 3; the ledger closes."""
    runs = {}
    for o, n in (("z", 1), ("x", 2), ("x", 3)):
        f = tmp_path / f"{o}.toml"
        f.write_text(SCENE.format(o=o, **AXES[o]))
        d = tmp_path / f"{o}{n}"
        res = run_cli(["run", str(f), "--out", str(d), "--quiet"], ranks=n, timeout=300)
        assert res.returncode == 0, res.stdout + res.stderr
        runs[o, n] = d / "run.h5"

    def fields(path):
        with h5py.File(path, "r") as f:
            return (f["geometry/x"][...], f["fields/u"][...], f["fields/damage"][...],
                    np.abs(f["energy/balance"][...]).max(), f["energy/gas"][...])

    xz, uz, dz, bz, gz = fields(runs["z", 1])
    xx, ux, dxx, bx, gx = fields(runs["x", 2])
    swap = [2, 1, 0]
    iz = np.lexsort(np.round(xz * 1e9).T[::-1])
    ix = np.lexsort(np.round(xx[:, swap] * 1e9).T[::-1])
    np.testing.assert_array_equal(xz[iz], xx[ix][:, swap])             # the same sites
    scale = np.abs(uz).max()
    assert scale > 1e-4                                                 # the charge did work
    assert np.abs(uz[:, iz] - ux[:, ix][:, :, swap]).max() < 1e-10 * scale
    assert np.array_equal(dz[:, iz], dxx[:, ix]) and (dz[-1] > 0).sum() > 100
    np.testing.assert_allclose(gz, gx, rtol=1e-10)
    assert bz < 1e-4 and bx < 1e-4, (bz, bx)
    with h5py.File(runs["x", 3], "r") as f:
        for k, a in (("fields/u", ux), ("fields/damage", dxx)):
            assert np.array_equal(f[k][...], a), f"{k} differs between 2 and 3 ranks"
    d = tmp_path / "r"
    res = run_cli(["run", str(tmp_path / "x.toml"), "--out", str(d), "--quiet",
                   "--stop-after", "60"], ranks=2, timeout=300)
    assert res.returncode == 0, res.stdout + res.stderr
    restart_matches(d / "checkpoint.h5", runs["x", 2], ("fields/u", "fields/damage"), ranks=3)
    # the bench measures need vertical holes: one line, status 2, for a hole along x
    res = subprocess.run([sys.executable, "-m", "mpipd.post", "bench", str(runs["x", 2])],
                         capture_output=True, text=True, timeout=120, env=child_env(),
                         cwd=tmp_path)
    assert res.returncode == 2 and "holes along z" in res.stderr, res.stderr
    assert len([ln for ln in res.stderr.splitlines() if ln.strip()]) == 1
    assert not (tmp_path / "bench").exists()                # nothing written


def test_part_points_lists_every_site():
    scene, _ = sc.load("blast_bench")
    rock = scene.parts[6]
    pts = part_points(rock)
    x, y = rock.shape.cross_section(rock.dx)
    assert len(pts) == len(x) * len(rock.shape.z_levels(rock.dx))


def test_near_a_rod_or_an_axis_hole_the_body_is_no_prism():
    """The interface correction's prism test (geometry.prisms_inside) is False within
    the reach of a rod or of a box's hole along another axis, and unchanged away from
    them; the reach may differ from point to point (an array)."""
    from types import SimpleNamespace as NS

    from mpipd.input.geometry import prisms_inside
    box = Box(lo=(0.0, 0.0, 0.0), hi=(0.02, 0.02, 0.02))
    rod = Rod(start=(0.0, 0.005, 0.005), end=(0.02, 0.005, 0.005), radius=0.001,
              inner_radius=0.0005)
    holed = Box(lo=box.lo, hi=box.hi, holes=(Hole(start=rod.start, end=rod.end, radius=0.001),))
    # far; 2.5 mm from the rod's surface (the last two: within the reach, then not)
    x = np.array([[0.01, 0.015, 0.015], [0.01, 0.005, 0.0075], [0.01, 0.005, 0.0085],
                  [0.01, 0.005, 0.0085]])
    reach = np.array([0.002, 0.002, 0.003, 0.002])
    base = prisms_inside([NS(shape=box, dx=1e-3)], x, reach)
    assert base.tolist() == [True, True, True, True]
    for parts in ([NS(shape=box, dx=1e-3), NS(shape=rod, dx=1e-3)], [NS(shape=holed, dx=1e-3)]):
        assert prisms_inside(parts, x, reach).tolist() == [True, False, False, True]
