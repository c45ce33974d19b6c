"""mpipd.post.lattice_bias on synthetic sections of a square lattice (the demo's
geometry: dx 1 mm, R_b 3.2 mm, R_o 30 mm; ring = crack-density zone 2,
12.13-21.07 mm): isotropic random failure is at the noise level (and the noise
level is the mean amplitude), a cross along the axes gives |c_4|/c_0 near 1,
six cracks at random angles give what their angles give, an all-failed ring
gives 0 although the lattice's own angular density is not uniform."""
import numpy as np
import pytest

from mpipd.post import cracks
from mpipd.post import lattice_bias as lb

DX, R_WALL, R_OUT = 1e-3, 3.2e-3, 30e-3
CENTER = (0.0, 0.0)


def section():
    """Rock points of one section: cell centres (i + 1/2) dx with R_b <= r <= R_o."""
    n = int(np.ceil(R_OUT / DX))
    c = (np.arange(-n, n) + 0.5) * DX
    x, y = (a.ravel() for a in np.meshgrid(c, c))
    r = np.hypot(x, y)
    keep = (r >= R_WALL) & (r <= R_OUT)
    return x[keep], y[keep]


def measure(x, y, failed):
    return lb.measure(x, y, failed, CENTER, DX, R_WALL, R_OUT)


def ray(x, y, deg, half_width=0.75 * DX):
    a = np.radians(deg)
    along = x * np.cos(a) + y * np.sin(a)
    perp = np.abs(-x * np.sin(a) + y * np.cos(a))
    return (perp < half_width) & (along > 0)


def in_ring(x, y):
    r0, r1 = lb.ring(R_WALL, R_OUT)
    r = np.hypot(x, y)
    return (r >= r0) & (r < r1)


def test_isotropic_random_failure_is_at_the_noise_level():
    x, y = section()
    failed = np.random.default_rng(7).random(len(x)) < 0.3
    m = measure(x, y, failed)
    zone2 = cracks.crack_density(x, y, failed, CENTER, DX, R_WALL, R_OUT)[1]
    assert m["ring_mm"] == pytest.approx(zone2["r_mm"], rel=1e-12)
    assert m["ring_mm"] == pytest.approx([12.1333, 21.0667], abs=1e-3)
    assert (m["n_points"], m["n_failed"]) == (zone2["points"], zone2["failed_points"])
    assert 200 < m["n_failed"] < 360
    assert m["noise"] == pytest.approx(0.5 * np.sqrt(np.pi) * np.sqrt(
        (m["n_points"] - m["n_failed"]) / (m["n_failed"] * (m["n_points"] - 1))))
    assert m["a4"] < 3 * m["noise"] and m["a8"] < 3 * m["noise"]


def test_noise_level_is_the_mean_amplitude_of_isotropic_failure():
    """400 draws with p = 1/2 (the finite-population factor (N - N_F)/(N - 1) = 1/2
    matters: without it the level would be sqrt(2) too high)."""
    x, y = section()
    ring = in_ring(x, y)
    theta = np.arctan2(y[ring], x[ring])
    rng = np.random.default_rng(11)
    ratio = {4: [], 8: []}
    for _ in range(400):
        failed = rng.random(ring.sum()) < 0.5
        noise = lb.noise_level(int(failed.sum()), len(theta))
        for k in ratio:
            ratio[k].append(abs(lb.modes(theta, failed, k)[0]) / noise)
    for k in ratio:
        assert np.mean(ratio[k]) == pytest.approx(1.0, abs=0.1), k


def expected_cross(r0, r1, rows, m):
    """|c_m|/c_0 of thin radial lines at perpendicular offsets ``rows`` (continuum: the
    angle of a point at distance t along the line is atan(s / t))."""
    num = den = 0.0
    for s in rows:
        t = np.linspace(np.sqrt(r0 ** 2 - s ** 2), np.sqrt(r1 ** 2 - s ** 2), 2001)
        f = np.cos(m * np.arctan(s / t))
        num += np.sum(0.5 * (f[1:] + f[:-1]) * np.diff(t))
        den += t[-1] - t[0]
    return num / den


def test_cross_along_the_axes_has_a_large_4_fold_amplitude():
    """Lines |y| < 2 dx and |x| < 2 dx (rows at +-0.5, +-1.5 dx): |c_4|/c_0 is
    1 - 8 <s^2/t^2> ~ 0.96, not the 1 of ideal thin lines; maxima on the axes."""
    x, y = section()
    failed = (np.abs(y) < 2 * DX) | (np.abs(x) < 2 * DX)
    m = measure(x, y, failed)
    r0, r1 = lb.ring(R_WALL, R_OUT)
    rows = np.array([0.5, 1.5]) * DX
    # the estimate subtracts the lattice's own |mu_4| ~ 0.009 (module docstring)
    assert m["a4"] == pytest.approx(expected_cross(r0, r1, rows, 4), abs=0.015)
    assert m["a8"] == pytest.approx(expected_cross(r0, r1, rows, 8), abs=0.02)
    assert 0.95 < m["a4"] < 0.98 and m["a4"] > 10 * m["noise"]
    assert min(m["a4_direction_deg"], 90 - m["a4_direction_deg"]) < 1.0
    assert m["n_failed"] == 4 * 4 * 9           # 4 arms x 4 rows x 9 points (12.5 ... 20.5 mm)
    assert m["major_radial_cracks"] == 4
    # thin lines (one row, |y| < dx/2 is empty: use the diagonals, perp = 0 exactly)
    diag = np.isclose(np.abs(x), np.abs(y))
    m = measure(x, y, diag)
    assert m["a4"] == pytest.approx(1.0, abs=0.02) and m["a8"] == pytest.approx(1.0, abs=0.02)
    assert m["a4_direction_deg"] == pytest.approx(45.0, abs=1e-6)


def test_six_cracks_at_random_angles():
    x, y = section()
    rng = np.random.default_rng(3)
    while True:                                 # six rays at least 30 deg apart
        deg = np.sort(rng.uniform(0, 360, 6))
        if np.diff(np.append(deg, deg[0] + 360)).min() > 30:
            break
    rays = [ray(x, y, d) for d in deg]
    failed = np.any(rays, axis=0)
    m = measure(x, y, failed)
    ring = in_ring(x, y)
    n = np.array([np.count_nonzero(q & ring) for q in rays])
    want = abs(np.sum(n * np.exp(-4j * np.radians(deg)))) / n.sum()
    assert m["a4"] == pytest.approx(want, abs=0.03)
    assert m["major_radial_cracks"] == 6
    cross = measure(x, y, (np.abs(y) < 2 * DX) | (np.abs(x) < 2 * DX))
    assert m["a4"] < 0.6 * cross["a4"]


def test_all_failed_ring_gives_zero_although_the_lattice_is_anisotropic():
    x, y = section()
    failed = np.hypot(x, y) < 25e-3              # crushed through the whole ring
    m = measure(x, y, failed)
    assert m["n_failed"] == m["n_points"] > 900
    assert m["a4"] < 1e-12 and m["a8"] < 1e-12 and m["noise"] == 0.0
    # the direct estimate without the all-points term would be |mu_4|, not 0
    assert m["lattice_a4"] > 1e-3


def test_no_failed_point_in_the_ring_is_not_available():
    x, y = section()
    m = measure(x, y, np.hypot(x, y) < 8e-3)
    assert set(m) == {"not_available"} and "ring" in m["not_available"]
