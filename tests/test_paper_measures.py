"""The paper's own measures in the report, on hand-built cases computed here: the
major radial cracks on Fig. 11's sections with lattice-neighbour linking, the
crushed zone at the frame nearest 4 µs (Fig. 9a), the gas outside the copper
tube's current inner surface, and the probes' snap warning."""
import math

import h5py
import numpy as np
import pytest
from conftest import granite, make_scene, scene_dict

from mpipd.input import scene as sc
from mpipd.post import cracks
from mpipd.post import tube as tb
from mpipd.post.analysis import first_damage_frame

DX, R_WALL, R_OUT = 1e-3, 3e-3, 30e-3


def section_lattice():
    """One section's points: cell centres ((i + 1/2) dx, (j + 1/2) dx) of the annulus
    R_WALL <= r <= R_OUT (as mpipd.input.geometry's lattice)."""
    n = int(R_OUT / DX) + 1
    i, j = np.meshgrid(np.arange(-n, n), np.arange(-n, n), indexing="ij")
    x, y = (i.ravel() + 0.5) * DX, (j.ravel() + 0.5) * DX
    r = np.hypot(x, y)
    keep = (r >= R_WALL) & (r <= R_OUT)
    return x[keep], y[keep]


def count(x, y, failed, link):
    return cracks.radial_cracks(x, y, failed, (0.0, 0.0), DX, R_WALL, R_OUT,
                                horizon=link)["count"]


def test_two_cracks_two_spacings_apart_stay_two_with_lattice_linking():
    """Two straight cracks along +x on the rows y = dx/2 and y = 5 dx/2, from the wall
    to the boundary: 2 dx apart over their whole length and at their tips, with the row
    between them intact.  Linked as lattice neighbours (1.5 dx) they are two major
    cracks; linked within the horizon (3 dx) they are one crack and one boundary arc."""
    x, y = section_lattice()
    rows = (np.isclose(y, 0.5 * DX) | np.isclose(y, 2.5 * DX)) & (x > 0)
    assert rows.sum() > 2 * 25                       # each row runs from ~3 mm to ~30 mm
    assert count(x, y, rows, cracks.LATTICE_LINK * DX) == 2
    assert count(x, y, rows, 3.0 * DX) == 1          # the horizon merges them
    # one row alone is one crack either way; the rows 1 dx apart (adjacent) are one crack
    one = np.isclose(y, 0.5 * DX) & (x > 0)
    assert count(x, y, one, cracks.LATTICE_LINK * DX) == 1 == count(x, y, one, 3.0 * DX)
    adjacent = (np.isclose(y, 0.5 * DX) | np.isclose(y, 1.5 * DX)) & (x > 0)
    assert count(x, y, adjacent, cracks.LATTICE_LINK * DX) == 1


def test_lattice_linking_joins_diagonal_neighbours_only():
    """A crack along the diagonal, one point per lattice cell (i, i): every step is a
    diagonal neighbour (sqrt(2) dx, max-norm 1 dx), so it is one crack.  The same
    diagonal with every other point removed has gaps of 2 dx (max-norm): no piece
    runs from zone 1 to the boundary, so no major crack (the horizon would still
    join it)."""
    x, y = section_lattice()
    diag = np.isclose(x, y) & (x > 0)
    assert count(x, y, diag, cracks.LATTICE_LINK * DX) == 1
    k = np.round(x / DX - 0.5).astype(int)
    gappy = diag & (k % 2 == 0)
    assert count(x, y, gappy, cracks.LATTICE_LINK * DX) == 0
    assert count(x, y, gappy, 3.0 * DX) == 1


def test_frame_nearest_4_us():
    """Fig. 9(a)'s first damage: the saved frame nearest 4 µs within 1 µs of it."""
    us = 1e-6
    assert first_damage_frame(np.array([0, 2, 4, 6, 8]) * us) == {"frame": 2, "t_us": 4.0}
    assert first_damage_frame(np.array([0, 3.2, 6.4]) * us)["frame"] == 1
    assert first_damage_frame(np.array([0, 3.5, 4.5]) * us)["frame"] == 1     # a tie: the first
    assert first_damage_frame(np.array([0, 2.5, 5.0, 7.5]) * us)["frame"] == 2   # 1 µs: kept
    for t in ([0, 10, 20], [0, 2.9, 5.1]):
        got = first_damage_frame(np.array(t) * us)
        assert "frame" not in got and "within 1 µs of 4 µs" in got["not_available"]
    assert "nearest is at 0 µs" in first_damage_frame(np.array([0, 10]) * us)["not_available"]


# ------------------------------------------------------------------ the tube
TUBE = {"part": 1, "name": "tube", "center": (0.0, 0.0), "r_in": 2.6e-3, "r_out": 3.2e-3,
        "z": (0.0, 6.0e-3), "dx": 0.3e-3, "charges": [0]}
NZ, NT = 10, 27          # round(6 mm / 0.6 mm), round(2 pi 2.6 mm / 0.6 mm) = round(27.2)


def at(r, iz, it, dz=0.0):
    """A current position at radius r in the middle of bin (iz, it)."""
    th = -math.pi + (it + 0.5) * 2 * math.pi / NT
    return [r * math.cos(th), r * math.sin(th), (iz + 0.5) * 0.6e-3 + dz]


def test_tube_grid_and_inner_layer():
    assert tb.grid(TUBE) == (NZ, NT)
    x = np.array([[2.75e-3, 0, 1e-3], [2.89e-3, 0, 1e-3], [2.91e-3, 0, 1e-3], [3.05e-3, 0, 1e-3]])
    np.testing.assert_array_equal(tb.inner_layer(x, TUBE), [True, True, False, False])


def test_gas_outside_the_current_inner_surface():
    """The inner surface: two inner-layer points per bin at 3.0 mm (one at 2.9 and one at
    3.1 mm: mean 3.0), except the bins (4, 5..7) bulged to 3.5 mm, and the bins
    (7, 20..22) that hold no point (their nearest ring of bins is at 3.0 mm).  Gas
    (current positions): at 2.9 mm (inside) and 3.1 mm (outside) in an ordinary bin,
    at 3.3 mm in the bulge (inside: its own bin's surface is 3.5 mm, though beyond
    the mean of the whole tube), at 3.05 mm in an empty bin (outside, against its
    neighbours' 3.0 mm) and 2.95 mm there (inside), and three points past the ends
    (z < 0 and z > 6 mm, whatever their radius): outside 2, beyond the ends 3."""
    inner = []
    for iz in range(NZ):
        for it in range(NT):
            if iz == 7 and it in (20, 21, 22):
                continue
            if iz == 4 and it in (5, 6, 7):
                inner += [at(3.4e-3, iz, it), at(3.6e-3, iz, it)]
            else:
                inner += [at(2.9e-3, iz, it, -0.1e-3), at(3.1e-3, iz, it, 0.1e-3)]
    inner = np.array(inner)
    rs = tb.surface(inner, TUBE)
    assert rs.shape == (NZ, NT)
    assert rs[0, 0] == pytest.approx(3.0e-3) and rs[4, 6] == pytest.approx(3.5e-3)
    assert rs[7, 21] == pytest.approx(3.0e-3)                # from its neighbours
    gas = np.array([at(2.9e-3, 2, 10), at(3.1e-3, 2, 11),     # inside, outside
                    at(3.3e-3, 4, 6),                         # inside the bulge
                    at(3.05e-3, 7, 21), at(2.95e-3, 7, 21),   # empty bin: outside, inside
                    [1e-3, 0.0, -0.2e-3], [1e-3, 0.0, 6.3e-3], [5e-3, 0.0, 6.1e-3]])
    assert tb.count(inner, gas, TUBE) == (2, 3)
    # against one mean radius for the whole tube the bulge's gas would be outside
    assert 3.3e-3 > np.hypot(inner[:, 0], inner[:, 1]).mean()
    # an intact tube (gas well inside): nothing outside, nothing beyond the ends
    assert tb.count(inner, np.array([at(2.0e-3, iz, 3) for iz in range(NZ)]), TUBE) == (0, 0)


def test_tubes_of_the_builtin_scenes():
    """blast_demo has one tube around its charge; blast_bench three, each around its own
    charge; elastic_wave none (the measure is then absent, not an error)."""
    from mpipd.post.model import _tubes

    def tubes(name):
        scene, _ = sc.load(name)
        names = [p.name for p in scene.parts]
        models = [scene.materials[p.material].registry_name for p in scene.parts]
        rock = tuple(k for k, n in enumerate(names) if n.startswith("rock"))
        return names, _tubes(names, {p.name: p for p in scene.parts}, models, rock)
    names, t = tubes("blast_demo")
    assert [(d["name"], d["r_in"], d["z"], d["dx"]) for d in t] == [("tube", 0.0026, (0.0, 0.006),
                                                                      3.0e-4)]
    assert [names[c] for c in t[0]["charges"]] == ["charge"]
    names, t = tubes("blast_bench")
    assert [(d["name"], [names[c] for c in d["charges"]]) for d in t] == [
        ("tube1", ["charge1"]), ("tube2", ["charge2"]), ("tube3", ["charge3"])]
    assert tubes("elastic_wave")[1] == []


# ------------------------------------------------------------------ probes
L = 0.0048


def test_probe_snap_warning(team):
    """A box of rock at dx 0.8 mm (lattice points at (i + 1/2) 0.8 mm): a probe on a
    lattice point, and one 0.3 dx off it along x, are not moved more than dx/2 and
    give no warning; one at the centre of a lattice cube of 8 points is moved
    sqrt(3) dx/2 = 0.693 mm > 0.4 mm and warns, naming the requested and the
    snapped positions and the distance.  The run file keeps both positions, the
    distance and the part's dx."""
    from mpipd.output.probes import Probes
    from mpipd.solver import Simulation
    d = scene_dict(None, parts=[{"name": "rock", "material": "rock", "dx": 0.8e-3,
                                 "shape": {"kind": "box", "lo": [0, 0, 0], "hi": [L, L, L]}}])
    d["materials"] = {"rock": granite()}
    on, off, mid = [0.002, 0.002, 0.002], [0.00224, 0.002, 0.002], [0.0024, 0.0024, 0.0024]
    d["probes"] = [{"name": "on", "position": on, "part": "rock"},
                   {"name": "off", "position": off, "part": "rock"},
                   {"name": "mid", "position": mid, "part": "rock"}]
    sim = Simulation(make_scene(d), team)
    pr = sim.probes
    assert isinstance(pr, Probes)
    assert pr.dist == pytest.approx([0.0, 0.24e-3, math.sqrt(3) * 0.4e-3], abs=1e-12)
    assert len(pr.notes) == 1
    note = pr.notes[0]
    assert note.startswith("probe 'mid' moved 0.693 mm (more than dx/2 = 0.4 mm")
    assert "requested position (2.4, 2.4, 2.4) mm" in note
    snapped = pr.x[2]
    assert all(abs(abs(c - 0.0024) - 0.0004) < 1e-12 for c in snapped)   # a cube corner
    assert "to the nearest point (" + ", ".join(f"{c * 1e3:.4g}" for c in snapped) + ") mm" in note
    with h5py.File("probes.h5", "w", driver="core", backing_store=False) as f:
        pr.create(f, 3)
        g = f["probes/mid"]
        np.testing.assert_allclose(g.attrs["position"], mid)
        np.testing.assert_allclose(g.attrs["x"], snapped)
        assert g.attrs["distance"] == pytest.approx(math.sqrt(3) * 0.4e-3)
        assert g.attrs["dx"] == pytest.approx(0.8e-3)
        np.testing.assert_allclose(f["probes/on"].attrs["x"], on)
