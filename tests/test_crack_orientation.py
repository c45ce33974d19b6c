"""Crack orientation (mpipd/post/crack_orientation.py) on synthetic sections whose
answer is known by construction: radial rays, a ring, an arc, random failure."""
import numpy as np
import pytest

from mpipd.post import crack_orientation as co
from mpipd.post import cracks

DX = 0.8e-3
R_WALL, R_OUT = 3.2e-3, 72e-3
HORIZON = 3 * DX


def _section():
    n = int(np.ceil(R_OUT / DX)) + 1
    g = (np.arange(-n, n + 1) + 0.5) * DX
    x, y = np.meshgrid(g, g, indexing="ij")
    x, y = x.ravel(), y.ravel()
    r = np.hypot(x, y)
    keep = (r >= R_WALL) & (r <= R_OUT)
    return x[keep], y[keep]


def _rays(x, y, angles_deg, width=DX):
    """Points within ``width`` of the rays from the axis at the given angles."""
    out = np.zeros(len(x), bool)
    for a in np.radians(angles_deg):
        along = x * np.cos(a) + y * np.sin(a)
        across = -x * np.sin(a) + y * np.cos(a)
        out |= (along > 0) & (np.abs(across) < width)
    return out


def _ring(x, y, radius, th0=-np.pi, th1=np.pi):
    th = np.arctan2(y, x)
    return (np.abs(np.hypot(x, y) - radius) < 0.6 * DX) & (th >= th0) & (th <= th1)


def _classes(m):
    return {c: sum(z[c]["points"] for z in m["zones"]) for c in co.CLASSES}


def test_direction_is_the_principal_axis_of_the_neighbourhood():
    """The closed-form 2x2 eigenvector against numpy's eigh, on random clusters."""
    rng = np.random.default_rng(3)
    pts = rng.normal(size=(40, 2)) * [3e-3, 0.5e-3]
    rot = np.radians(37.0)
    pts = pts @ np.array([[np.cos(rot), np.sin(rot)], [-np.sin(rot), np.cos(rot)]])
    big = np.full(len(pts), 1.0)            # every point sees every other
    t, ratio, count = co.local_directions(pts[:, 0], pts[:, 1], np.ones(len(pts), bool), big)
    d = pts - pts.mean(axis=0)
    lam, vec = np.linalg.eigh(d.T @ d / len(pts))
    assert np.all(count == len(pts))
    assert np.allclose(np.abs(t @ vec[:, 1]), 1.0, atol=1e-12)
    assert np.allclose(ratio, lam[0] / lam[1], rtol=1e-10)


def test_radial_rays_are_radial():
    x, y = _section()
    failed = _rays(x, y, [10, 70, 130, 190, 250, 310])
    m = co.measure(x, y, failed, (0.0, 0.0), DX, R_WALL, R_OUT, HORIZON)
    outer = [z for z in m["zones"] if z["zone"] > 1]
    rad = sum(z["radial"]["points"] for z in outer)
    circ = sum(z["circumferential"]["points"] for z in outer)
    assert rad > 0.95 * sum(z["failed_points"] for z in outer)
    assert circ == 0
    assert m["ring_arcs"] == 0


def test_a_ring_is_circumferential_with_its_length():
    x, y = _section()
    failed = _ring(x, y, 40e-3)
    m = co.measure(x, y, failed, (0.0, 0.0), DX, R_WALL, R_OUT, HORIZON)
    c = _classes(m)
    assert c["circumferential"] > 0.95 * np.count_nonzero(failed)
    assert m["ring_arcs"] == 1
    # the arc's length is geometric: 2 pi R whatever the band's width
    assert m["ring_arc_length_mm"] == pytest.approx(2 * np.pi * 40.0, rel=0.01)
    # the per-zone class length follows Fig. 12 (each point stands for dx): the band
    # |r - R| < 0.6 dx holds about 1.2 x 2 pi R / dx points
    assert m["zones"][1]["circumferential"]["length_mm"] == pytest.approx(
        1.2 * 2 * np.pi * 40.0, rel=0.05)
    z2 = m["zones"][1]                       # 26.1-49.1 mm holds r = 40 mm
    area = np.pi * (z2["r_mm"][1] ** 2 - z2["r_mm"][0] ** 2)
    assert z2["circumferential_density_mm_per_mm2"] == pytest.approx(
        z2["circumferential"]["length_mm"] / area)
    assert z2["circumferential"]["points"] == c["circumferential"]


def test_an_arc_between_rays_is_one_ring_arc_and_a_short_one_none():
    x, y = _section()
    arc = _ring(x, y, 40e-3, np.radians(20), np.radians(60))
    short = _ring(x, y, 60e-3, np.radians(100), np.radians(100) + 1.5 * HORIZON / 60e-3)
    failed = _rays(x, y, [10, 70, 130, 190, 250, 310]) | arc | short
    m = co.measure(x, y, failed, (0.0, 0.0), DX, R_WALL, R_OUT, HORIZON)
    assert m["ring_arcs"] == 1
    assert m["rings"][0]["r_mm"] == pytest.approx(40.0, abs=0.5)
    # R x the angle (the ends' few points unclassed)
    assert m["rings"][0]["length_mm"] == pytest.approx(40.0 * np.radians(40), rel=0.08)
    assert m["rings"][0]["points"] > 0.9 * np.count_nonzero(arc)


def test_a_short_wide_arc_is_not_a_ring_arc():
    """An arc 1.5 horizons long and two points wide: 2 x its length in points x dx,
    but shorter than two horizons."""
    x, y = _section()
    th0 = np.radians(100)
    th1 = th0 + 1.5 * HORIZON / 40e-3
    th = np.arctan2(y, x)
    wide = (np.abs(np.hypot(x, y) - 40e-3) < DX) & (th >= th0) & (th <= th1)
    m = co.measure(x, y, wide, (0.0, 0.0), DX, R_WALL, R_OUT, HORIZON)
    assert np.count_nonzero(wide) * DX > 2 * HORIZON       # points x dx would count it
    assert _classes(m)["circumferential"] > 0.5 * np.count_nonzero(wide)
    assert m["ring_arcs"] == 0


def test_oblique_and_isolated():
    """Lines at 45 deg to the radius are oblique; lone points are isolated."""
    x, y = _section()
    failed = np.zeros(len(x), bool)
    for cx, cy in ((30e-3, 0.0), (0.0, -45e-3), (-40e-3, 20e-3)):
        # a line through (cx, cy) at 45 deg to e_r there
        a = np.arctan2(cy, cx) + np.pi / 4
        along = (x - cx) * np.cos(a) + (y - cy) * np.sin(a)
        across = -(x - cx) * np.sin(a) + (y - cy) * np.cos(a)
        failed |= (np.abs(along) < 4e-3) & (np.abs(across) < 0.5 * DX)
    lone = [np.argmin(np.hypot(x - px, y - py)) for px, py in ((20e-3, 40e-3), (-60e-3, -5e-3))]
    failed[lone] = True
    cls = co.classify(x, y, failed, (0.0, 0.0), HORIZON)
    assert np.all(cls[lone] == co.CLASSES.index("isolated"))
    line = failed.copy()
    line[lone] = False
    c = cls[line]
    assert np.count_nonzero(c == co.CLASSES.index("oblique")) > 0.8 * len(c)   # ends: few
    assert not np.any((c == co.CLASSES.index("radial")) | (c == co.CLASSES.index("circumferential")))


def test_each_point_uses_its_own_horizon():
    """A point whose own horizon is below its neighbours' spacing sees only itself
    (isolated), even though the neighbours' horizons reach it."""
    x = np.arange(10) * 1e-3 + 30e-3
    y = np.zeros(10)
    h = np.full(10, 3.1e-3)
    h[5] = 0.5e-3
    t, ratio, count = co.local_directions(x, y, np.ones(10, bool), h)
    assert count[5] == 1
    assert count[4] == 7 and count[0] == 4      # points within 3.1 mm, itself included
    assert np.allclose(np.abs(t[[0, 4, 9]][:, 0]), 1.0) and np.allclose(ratio[[0, 4, 9]], 0)


def test_random_failure_has_no_preferred_direction():
    """Failure independent of direction: about a third of the classified points in
    each class (psi uniform on [0, 90 deg])."""
    x, y = _section()
    rng = np.random.default_rng(11)
    failed = (rng.random(len(x)) < 0.12) & (np.hypot(x, y) > 26e-3)
    c = _classes(co.measure(x, y, failed, (0.0, 0.0), DX, R_WALL, R_OUT, HORIZON))
    n = c["radial"] + c["oblique"] + c["circumferential"]
    assert n > 500
    for k in ("radial", "oblique", "circumferential"):
        assert 0.25 < c[k] / n < 0.42, (k, c[k] / n)


def test_no_failure():
    x, y = _section()
    m = co.measure(x, y, np.zeros(len(x), bool), (0.0, 0.0), DX, R_WALL, R_OUT, HORIZON)
    assert m["ring_arcs"] == 0 and all(z["failed_points"] == 0 for z in m["zones"])


# Failed rings: rings of width dx beyond the crushed zone with at least half their
# points failed, under half of those radial.

def _rings(x, y, failed):
    return co.measure(x, y, failed, (0.0, 0.0), DX, R_WALL, R_OUT, horizon=HORIZON)["failed_rings"]


def test_a_wide_spall_band_is_a_failed_ring_and_the_crushed_zone_is_not():
    x, y = _section()
    r = np.hypot(x, y)
    band = (r >= 60e-3) & (r < 64e-3)                 # five spacings wide
    failed = (r < 10e-3) | band | _rays(x, y, np.arange(0, 360, 30))
    rings = _rings(x, y, failed)
    assert len(rings) == 1
    lo, hi = rings[0]["r_mm"]
    assert 59.2 - 1e-9 <= lo <= 60.0 + 1e-9 and 64.0 - 1e-9 <= hi <= 64.8 + 1e-9
    assert rings[0]["peak_fraction"] == pytest.approx(1.0)
    crushed = cracks.crushed_zone(x, y, failed, (0.0, 0.0), DX, R_WALL, R_OUT)
    assert 6.4 - 1e-9 <= crushed["extent_mm"] <= 7.2 + 1e-9        # 10 mm less the wall
    # the band is five points wide: the local direction leaves most of it unresolved
    m = co.measure(x, y, band, (0.0, 0.0), DX, R_WALL, R_OUT, horizon=HORIZON)
    assert m["zones"][2]["unresolved"]["points"] > 0.5 * np.count_nonzero(band)


def test_the_crushed_zone_reports_what_failed_its_points():
    """A disc crushed to 7.2 mm (five rings of dx beyond the 3.2 mm wall): JH2 plastic
    (mode 1) inside 5.6 mm, the tension model (mode 3) beyond, one point there whose bonds
    all broke with its own state intact (mode 0), one point in the innermost ring that did
    not fail (it does not count), and tension rays past the disc that are not the crushed
    zone's: the shares are the counts by radius."""
    x, y = _section()
    r = np.hypot(x, y)
    disc = r < 7.2e-3
    failed = disc | _rays(x, y, np.arange(0, 360, 45))
    mode = np.where(failed, np.where(r < 5.6e-3, 1, 3), 0)
    lone = np.flatnonzero(disc & (r > 6.4e-3))[0]
    mode[lone] = 0
    whole = np.flatnonzero(disc & (r < 4.0e-3))[0]     # one of about 28 in its ring
    failed[whole] = False
    mode[whole] = 0
    crushed = cracks.crushed_zone(x, y, failed, (0.0, 0.0), DX, R_WALL, R_OUT, mode=mode)
    assert crushed["extent_mm"] == pytest.approx(4.0)
    n = np.count_nonzero(disc) - 1
    share = crushed["mode_share"]
    assert share["JH2 plastic (D >= 1)"] == pytest.approx((np.count_nonzero(r < 5.6e-3) - 1) / n)
    assert share["tension model (Eq. 38)"] == pytest.approx(
        (np.count_nonzero(disc & (r >= 5.6e-3)) - 1) / n)
    assert share["intact"] == pytest.approx(1 / n) and share["JH2 tensile (p < -T)"] == 0.0
    with pytest.raises(ValueError, match="failure modes"):
        cracks.crushed_zone(x, y, failed, (0.0, 0.0), DX, R_WALL, R_OUT, mode=mode + 4)
    assert "mode_share" not in cracks.crushed_zone(x, y, failed, (0.0, 0.0), DX, R_WALL, R_OUT)
    none = cracks.crushed_zone(x, y, np.zeros(len(x), bool), (0.0, 0.0), DX, R_WALL, R_OUT,
                               mode=mode)
    assert none["extent_mm"] == 0.0 and none["mode_share"] == {}


def test_a_complete_ring_two_points_wide_is_a_failed_ring():
    x, y = _section()
    r = np.hypot(x, y)
    rings = _rings(x, y, np.abs(r - 40e-3) < DX)
    assert len(rings) == 1
    assert rings[0]["r_mm"][0] <= 40.0 <= rings[0]["r_mm"][1]


@pytest.mark.parametrize("what", ["rays", "arc", "random"])
def test_radial_cracks_an_arc_and_random_failure_make_no_failed_ring(what):
    x, y = _section()
    r = np.hypot(x, y)
    if what == "rays":              # 12 rays two points wide: 12 * 2 dx / (2 pi r) failed,
        failed = _rays(x, y, np.arange(0, 360, 30))     # over 1/2 inside r = 6.1 mm
        k, nb, w = cracks.ring_index(x, y, (0.0, 0.0), DX, R_WALL, R_OUT)
        frac = np.bincount(k[failed], minlength=nb) / np.bincount(k, minlength=nb)
        assert frac[2:8].max() >= co.RING_FRACTION
    elif what == "arc":             # a band a third of the way round
        th = np.arctan2(y, x)
        failed = (r >= 40e-3) & (r < 44e-3) & (np.abs(th) < np.pi / 3)
    else:
        failed = np.random.default_rng(3).random(len(x)) < 0.3
    assert _rings(x, y, failed) == []


def test_ring_history_finds_a_ring_that_radial_damage_later_overruns():
    """analysis.ring_history: an arc on one section at frame 2, overrun by radial rays
    every 4 deg at frame 3; a ring at 5 mm at frame 1, inside the crushed radius given
    (6 mm), is left out.  The last frame (the report's headline) has no ring arc;
    the history has it at frame 2, R x the angle long, and its largest mean over the
    three sections is that length / 3 at frame 2's time."""
    from types import SimpleNamespace

    from mpipd.post import analysis
    x, y = _section()
    rays = _rays(x, y, [10, 70, 130, 190, 250, 310])
    arc = _ring(x, y, 40e-3, np.radians(20), np.radians(60))
    over = _rays(x, y, np.arange(14, 68, 4.0))
    wall = _ring(x, y, 5e-3)                 # inside the crushed radius given, 6 mm
    inner = co.measure(x, y, rays | wall, (0.0, 0.0), DX, R_WALL, R_OUT, HORIZON)["rings"]
    assert inner and all(a["r_mm"] == pytest.approx(5.0, abs=0.5) for a in inner)
    damage = {1: rays | wall, 2: rays | arc, 3: rays | arc | over}
    sections = {}
    for i, name in enumerate(analysis.CRACK_SECTIONS):
        sec = {"x": x, "y": y, "h": np.full(len(x), DX), "link": np.full(len(x), HORIZON)}
        for k, f in damage.items():
            sec[("damage", k)] = np.where(f if i == 1 else rays, 1.0, 0.0)
        sections[name] = sec
    model = SimpleNamespace(center=(0.0, 0.0), r_wall=R_WALL, r_out=R_OUT)
    h = analysis.ring_history(sections, model, [1, 2, 3], [0.0, 10e-6, 20e-6, 30e-6],
                              {n: 6.0 for n in analysis.CRACK_SECTIONS})
    arcs = {n: [row["ring_arcs"] for row in rows] for n, rows in h["sections"].items()}
    with_arc = analysis.CRACK_SECTIONS[1]
    assert arcs[with_arc] == [0, 1, 0]
    assert all(a == [0, 0, 0] for n, a in arcs.items() if n != with_arc)
    length = h["sections"][with_arc][1]["ring_arc_length_mm"]
    assert length == pytest.approx(40.0 * np.radians(40), rel=0.08)
    assert h["sections"][with_arc][1]["radii_mm"] == [pytest.approx(40.0, abs=0.5)]
    assert h["mean_length_mm"] == pytest.approx([0.0, length / 3, 0.0])
    assert h["largest"] == {"length_mm": pytest.approx(length / 3), "frame": 2,
                            "t_us": pytest.approx(20.0)}
