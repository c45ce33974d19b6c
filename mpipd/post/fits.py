"""Least-squares fits used by the report.

* straight line ``y = a x + b`` (the wave speed of Fig. 16b: distance against
  the arrival time of the peak, slope = speed);
* power law ``y = C d^-n`` fitted as the line ``ln y = ln C - n ln d`` (the
  attenuation of the peak radial stress, Fig. 17, paper n = 0.798; and the
  Holmberg–Persson PPV law ``PPV = K d^-beta``, Fig. 18);
* the time of a sampled peak, refined by the parabola through the largest
  sample and its two neighbours.

Every fit returns a dict with the coefficients, ``r2`` (coefficient of
determination of the fitted line) and ``n_points``.
"""
from __future__ import annotations

import numpy as np


class FitError(ValueError):
    pass


def line(x, y) -> dict:
    x, y = np.asarray(x, float), np.asarray(y, float)
    if len(x) < 2 or np.ptp(x) == 0:
        raise FitError(f"a line needs 2 or more distinct abscissae (got {len(x)})")
    a, b = np.polyfit(x, y, 1)
    res = y - (a * x + b)
    ss = float(((y - y.mean()) ** 2).sum())
    r2 = 1.0 - float((res ** 2).sum()) / ss if ss > 0 else 1.0
    return {"slope": float(a), "intercept": float(b), "r2": r2, "n_points": int(len(x))}


def power_law(d, y) -> dict:
    """``y = C d^-n`` through positive (d, y) pairs: returns C (units of y at d = 1 of
    the units of d), n, r2 in log space."""
    d, y = np.asarray(d, float), np.asarray(y, float)
    ok = (d > 0) & (y > 0) & np.isfinite(d) & np.isfinite(y)
    if ok.sum() < 2:
        raise FitError(f"a power law needs 2 or more positive points (got {int(ok.sum())})")
    f = line(np.log(d[ok]), np.log(y[ok]))
    return {"C": float(np.exp(f["intercept"])), "n": float(-f["slope"]), "r2": f["r2"],
            "n_points": f["n_points"]}


def peak_time(t, y) -> tuple[float, float, bool]:
    """(time, value, interior) of the largest sample y_k of ``y`` (NaNs ignored).

    Inside the record (0 < k < n - 1, ``interior`` True) the time is the vertex of the
    parabola through (t_k-1, y_k-1), (t_k, y_k), (t_k+1, y_k+1):
        t = t_k + s h,  s = (y_k-1 - y_k+1) / (2 (y_k-1 - 2 y_k + y_k+1)),
    s clamped to [-1/2, 1/2] (0 if the denominator is 0) and h the step on the
    side of the shift (t_k+1 - t_k for s >= 0, t_k - t_k-1 otherwise).  At the first or
    last sample, (t_k, y_k, False): the peak may lie outside the record."""
    t, y = np.asarray(t, float), np.asarray(y, float)
    k = int(np.nanargmax(y))
    if k == 0 or k == len(y) - 1:
        return float(t[k]), float(y[k]), False
    y0, y1, y2 = y[k - 1:k + 2]
    den = y0 - 2 * y1 + y2
    s = 0.5 * (y0 - y2) / den if den != 0 else 0.0
    s = min(max(s, -0.5), 0.5)
    h = t[k + 1] - t[k] if s >= 0 else t[k] - t[k - 1]
    return float(t[k] + s * h), float(y1), True
