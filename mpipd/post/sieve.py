"""The fragment-size distribution: the mass passing curve, its percentiles and fits.

Passing curve.  With fragments sorted by size x_i (a sieve size, mpipd's
mpipd.post.fragments), P(x_i) is the mass fraction of the fragments of size
<= x_i.  The percentile X_q (X20, X50, X80) is the size where P reaches q,
interpolated linearly in ln x between the fragment below q and the one that
reaches it (the size of the fragment itself when it alone carries P across q
from the smallest size).

Fits (least squares on P over the curve's points, in the parameters' logs):

* Rosin–Rammler in its median form (Ouchterlony 2016, Blasting & Fragmentation 10):
      P(x) = 1 - exp(-ln 2 (x / x50)^n),   n the uniformity index;
* Swebrec (Ouchterlony 2005, Mining Technology 114):
      P(x) = 1 / (1 + [ln(xmax / x) / ln(xmax / x50)]^b)   (0 < x < xmax), 1 beyond,
  with xmax the largest size (at least the largest fragment's) and b the undulation.

Each fit reports its parameters and R^2 on P.  A curve with fewer than 4
fragments is not fitted.
"""
from __future__ import annotations

import math

import numpy as np
from scipy.optimize import least_squares

LN2 = math.log(2.0)


def passing(size: np.ndarray, mass: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(x, P): sizes ascending and the cumulative mass fraction passing each."""
    order = np.argsort(size, kind="stable")
    x = np.asarray(size, float)[order]
    P = np.cumsum(np.asarray(mass, float)[order])
    return x, P / P[-1]


def percentile(x: np.ndarray, P: np.ndarray, q: float) -> float:
    """X_q: the size where the passing curve (x, P) reaches q (0 < q <= 1)."""
    k = int(np.searchsorted(P, q - 1e-12))
    if k == 0:
        return float(x[0])
    x0, x1, p0, p1 = x[k - 1], x[k], P[k - 1], P[k]
    if p1 <= p0 or x0 <= 0.0:
        return float(x1)
    return float(math.exp(math.log(x0) + (q - p0) / (p1 - p0) * (math.log(x1) - math.log(x0))))


def rosin_rammler(x, x50, n):
    return 1.0 - np.exp(-LN2 * (np.asarray(x, float) / x50) ** n)


def swebrec(x, x50, xmax, b):
    x = np.asarray(x, float)
    inside = x < xmax
    r = np.log(xmax / np.where(inside, x, xmax * 0.5)) / math.log(xmax / x50)
    return np.where(inside, 1.0 / (1.0 + np.abs(r) ** b), 1.0)


def _r2(P, model):
    ss = float(np.sum((P - P.mean()) ** 2))
    return 1.0 - float(np.sum((P - model) ** 2)) / ss if ss > 0 else float("nan")


def fit_rosin_rammler(x, P) -> dict | None:
    if len(x) < 4:
        return None
    x50 = percentile(x, P, 0.5)
    res = least_squares(lambda q: rosin_rammler(x, math.exp(q[0]), math.exp(q[1])) - P,
                        [math.log(x50), 0.0])
    x50, n = math.exp(res.x[0]), math.exp(res.x[1])
    return {"x50": x50, "n": n, "x80": x50 * (math.log(5.0) / LN2) ** (1.0 / n),
            "r2": _r2(P, rosin_rammler(x, x50, n))}


def fit_swebrec(x, P) -> dict | None:
    if len(x) < 4:
        return None
    x50 = percentile(x, P, 0.5)
    top = float(x[-1])

    def model(q):
        xmax = top * (1.0 + math.exp(q[1]))                   # xmax > the largest size
        x50 = min(math.exp(q[0]), 0.999 * xmax)
        return swebrec(x, x50, xmax, math.exp(q[2])), x50, xmax

    res = least_squares(lambda q: model(q)[0] - P, [math.log(min(x50, 0.9 * top)), -2.0, 0.5])
    fitted, x50, xmax = model(res.x)
    b = math.exp(res.x[2])
    return {"x50": x50, "xmax": xmax, "b": b,
            "x80": xmax * (x50 / xmax) ** (0.25 ** (1.0 / b)), "r2": _r2(P, fitted)}


def summary(size, mass) -> dict:
    """Percentiles, the fits and the curve of fragments of ``size`` and ``mass``."""
    x, P = passing(size, mass)
    return {"x20": percentile(x, P, 0.2), "x50": percentile(x, P, 0.5),
            "x80": percentile(x, P, 0.8), "rosin_rammler": fit_rosin_rammler(x, P),
            "swebrec": fit_swebrec(x, P), "curve": (x, P)}
