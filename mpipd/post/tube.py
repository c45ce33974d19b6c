"""Gas containment by the tube: does the explosive gas stay inside the copper tube?

The paper's copper tube "passes the blasting load onto the rock" (§3.1, Fig. 6);
an intact tube holds the gas, so no gas point should lie outside it while the tube
is whole.  The tube is a part of the scene that holds a charge
(:attr:`mpipd.post.model.Model.tubes`: an annulus around a ``jwl`` cylinder on the
same axis); the gas is the points of the charges it holds (material model
``jwl``).  Current positions are y = x + u of the frame (``/geometry/x`` and
``/fields/u``: the gas is updated-Lagrangian, its ``u`` is its current position
minus its reference one, as for every other point, mpipd.model.gas).

Per saved frame and tube:

* the **inner layer**: the tube's points whose reference radius r_ref (about the
  tube's axis) is within one copper dx of the tube's inner radius,
  r_ref - R_in < dx_tube (the innermost lattice layer: every point has
  r_ref >= R_in);
* the **current inner surface**: the inner-layer points binned by their current
  (z, angle) on a grid of bins about two copper dx wide (nz = round(L / 2 dx) bins
  over the tube's length L = z1 - z0, n_theta = round(2 pi R_in / 2 dx) bins of angle;
  a point beyond an end goes to the end bin), and in each bin the mean current
  radius of its inner-layer points, R_s(bin).  A bin without an inner-layer point
  takes the pooled mean of the nearest non-empty bins (the smallest square ring of
  bins around it, angle wrapping, that holds any);
* a gas point with current z outside [z0, z1] (the tube's axial extent, from the
  scene) is **beyond the ends** (venting through the open ends: counted apart);
* a gas point with z0 <= z <= z1 is **outside** the tube when its current radius
  exceeds R_s of the bin of its current (z, angle).

The bins' means are formed from the inner layer gathered to every rank in gid
order, so the counts do not depend on the number of reading ranks.  With an intact
tube ``outside`` is 0 at every frame; the report judges it so
(:data:`mpipd.post.targets.TARGETS` ``gas_outside_tube``) and gives the first
frame where it is not.
"""
from __future__ import annotations

import numpy as np

INNER_LAYER = 1.0       # the inner layer: r_ref - R_in < INNER_LAYER dx_tube
BIN = 2.0               # bin size, in dx_tube, along z and along the arc at R_in

RULE = ("gas points (the tube's charges, current position x + u) with z0 <= z <= z1 "
        "whose current radius exceeds the mean current radius of the tube's inner-layer "
        "points (reference radius within one copper dx of its inner radius) in their "
        "(z, angle) bin, bins about two copper dx wide (an empty bin: the nearest "
        "non-empty ones); beyond the ends: gas points with z outside [z0, z1]")


def grid(tube) -> tuple[int, int]:
    """(nz, n_theta): bins about BIN dx_tube wide along z and along the arc at R_in."""
    z0, z1 = tube["z"]
    w = BIN * tube["dx"]
    return (max(1, int(round((z1 - z0) / w))),
            max(1, int(round(2.0 * np.pi * tube["r_in"] / w))))


def _polar(y, tube):
    dx, dy = y[:, 0] - tube["center"][0], y[:, 1] - tube["center"][1]
    return np.hypot(dx, dy), np.arctan2(dy, dx)


def bins(y, tube) -> tuple[np.ndarray, np.ndarray]:
    """Bin indices (iz, it) of current positions ``y`` (z clipped to the end bins)."""
    nz, nt = grid(tube)
    z0, z1 = tube["z"]
    _, th = _polar(y, tube)
    iz = np.clip(np.floor((y[:, 2] - z0) / (z1 - z0) * nz).astype(np.int64), 0, nz - 1)
    it = np.floor((th + np.pi) / (2.0 * np.pi) * nt).astype(np.int64) % nt
    return iz, it


def inner_layer(x_ref, tube) -> np.ndarray:
    """Mask of the tube's points (reference positions ``x_ref``) in its inner layer."""
    r, _ = _polar(x_ref, tube)
    return r - tube["r_in"] < INNER_LAYER * tube["dx"]


def surface(y_inner, tube) -> np.ndarray:
    """(nz, n_theta) radius of the current inner surface from the inner layer's current
    positions ``y_inner``: each bin's mean current radius, an empty bin the pooled mean
    of the nearest ring of bins that holds inner-layer points (NaN if none holds any)."""
    nz, nt = grid(tube)
    r, _ = _polar(y_inner, tube)
    iz, it = bins(y_inner, tube)
    key = iz * nt + it
    s = np.bincount(key, weights=r, minlength=nz * nt).reshape(nz, nt)
    c = np.bincount(key, minlength=nz * nt).reshape(nz, nt).astype(float)
    out = np.full((nz, nt), np.nan)
    have = c > 0
    out[have] = s[have] / c[have]
    if not have.any():
        return out
    for a, b in zip(*np.nonzero(~have)):
        for d in range(1, max(nz, nt) + 1):
            rows = np.arange(max(0, a - d), min(nz, a + d + 1))
            cols = np.unique(np.arange(b - d, b + d + 1) % nt)
            cs = c[np.ix_(rows, cols)].sum()
            if cs > 0:
                out[a, b] = s[np.ix_(rows, cols)].sum() / cs
                break
    return out


def count(y_inner, y_gas, tube) -> tuple[int, int]:
    """(outside, beyond the ends): the gas points (current positions ``y_gas``) outside
    the current inner surface within the tube's axial extent, and those beyond its
    ends (module docstring); ``y_inner``: the inner layer's current positions."""
    if not len(y_gas):
        return 0, 0
    z0, z1 = tube["z"]
    along = (y_gas[:, 2] >= z0) & (y_gas[:, 2] <= z1)
    beyond = int(np.count_nonzero(~along))
    if not along.any() or not len(y_inner):
        return 0, beyond
    rs = surface(y_inner, tube)
    yg = y_gas[along]
    r, _ = _polar(yg, tube)
    iz, it = bins(yg, tube)
    return int(np.count_nonzero(r > rs[iz, it])), beyond


class Containment:
    """The measure over a run's frames (collective: every rank calls every method)."""

    def __init__(self, run, model, x, pid):
        self.run, self.tubes = run, list(model.tubes)
        self.inner = [np.flatnonzero((pid == t["part"]) & inner_layer(x, t)) for t in self.tubes]
        self.gas = [np.flatnonzero(np.isin(pid, t["charges"])) for t in self.tubes]
        self.x = x
        self.outside = np.zeros((len(self.tubes), run.frames), np.int64)
        self.beyond = np.zeros((len(self.tubes), run.frames), np.int64)

    def frame(self, k: int, u: np.ndarray):
        """Frame ``k`` with this rank's displacements ``u``."""
        for i, t in enumerate(self.tubes):
            yi = np.concatenate(self.run.comm.allgather(self.x[self.inner[i]] + u[self.inner[i]]))
            g = self.gas[i]
            o, b = count(yi, self.x[g] + u[g], t)
            self.outside[i, k], self.beyond[i, k] = self.run.sum_int(o), self.run.sum_int(b)

    def result(self) -> dict:
        run = self.run
        t_us = [float(t) * 1e6 for t in run.time]
        out = self.outside.sum(axis=0)
        bey = self.beyond.sum(axis=0)
        bad = np.flatnonzero(out > 0)
        first = (None if not len(bad) else
                 {"frame": int(bad[0]), "t_us": t_us[bad[0]], "points": int(out[bad[0]])})
        return {"rule": RULE, "tubes": [t["name"] for t in self.tubes],
                "bins": [list(grid(t)) for t in self.tubes],
                "inner_layer_points": [run.sum_int(len(i)) for i in self.inner],
                "gas_points": [run.sum_int(len(g)) for g in self.gas],
                "t_us": t_us, "outside": out.tolist(), "beyond_ends": bey.tolist(),
                "max_outside": int(out.max()), "max_beyond_ends": int(bey.max()),
                "first_outside": first}
