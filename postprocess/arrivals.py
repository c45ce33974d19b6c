"""Arrival of the stress wave at a probe, from its every-step record of -sigma_rr.

* Threshold: ``FRACTION`` = 10 % of the probe's own peak -sigma_rr over the record.
* First arrival: the first time -sigma_rr reaches the threshold, linearly
  interpolated between the sample below and the sample at or above it.  A record
  already above the threshold at its first sample has no arrival.
* First pulse: the samples from the arrival until -sigma_rr falls below half of its
  running maximum since the arrival (or the end of the record).  If the global peak
  lies after that, the peak belongs to a later pulse (a reflection) and the paper's
  peak-arrival time is not the arrival of the direct wave.
* Wave speed: the least-squares slope of distance against first-arrival time over
  probes A–G; the arrival times must increase with distance from the wall, else the
  measure is an error, not a speed.
* Threshold study (information): the same speed at the fractions ``STUDY`` of each
  probe's peak.  For pulses of one shape the speed does not depend on the fraction;
  when the pulse broadens or steepens as it travels (rise times that grow with
  distance, a shock that steepens) the arrival at a fixed fraction is a different
  phase of the pulse at each probe, and the speeds part.  Their spread tells how much
  of the judged value is the measure rather than the wave.
"""
from __future__ import annotations

import numpy as np

FRACTION = 0.10              # threshold = 10 % of the probe's peak -sigma_rr
STUDY = (0.02, 0.05, 0.10, 0.20, 0.50)   # fractions of the threshold study
PULSE_END = 0.5              # the first pulse ends below half its running maximum
THRESHOLD_TEXT = "10 % of each probe's peak −σ_rr over its record, linearly interpolated"


def first_arrival(t, y, fraction: float = FRACTION) -> dict:
    """Arrival of the compressive pulse ``y`` = -sigma_rr (Pa) sampled at ``t`` (s), at
    ``fraction`` of its peak."""
    t, y = np.asarray(t, float), np.asarray(y, float)
    if len(y) < 2 or not np.isfinite(y).any():
        return {"not_available": "no samples"}
    kp = int(np.nanargmax(y))
    peak = float(y[kp])
    if not peak > 0:
        return {"not_available": "no compressive pulse (−σ_rr never positive)"}
    thr = fraction * peak
    k = int(np.argmax(y >= thr))
    if k == 0:
        return {"not_available": "−σ_rr is at or above the threshold at the first sample"}
    y0, y1 = y[k - 1], y[k]
    ta = float(t[k - 1] + (thr - y0) / (y1 - y0) * (t[k] - t[k - 1]))
    run_max = np.maximum.accumulate(y[k:])
    below = np.flatnonzero(y[k:] < PULSE_END * run_max)
    end = k + int(below[0]) if len(below) else len(y) - 1
    return {"t_s": ta, "threshold_Pa": thr, "peak_Pa": peak, "t_peak_s": float(t[kp]),
            "first_pulse_end_s": float(t[end]), "first_pulse_peak_Pa": float(y[k:end + 1].max()),
            "peak_in_first_pulse": kp <= end}


def speed(names, d, t) -> dict:
    """Least-squares slope of d (m) against t (s) for arrivals increasing with d; an
    ``{"error": ...}`` when they do not."""
    order = np.argsort(d, kind="stable")
    bad = [(names[a], d[a], t[a], names[b], d[b], t[b])
           for a, b in zip(order[:-1], order[1:]) if not t[b] > t[a]]
    if bad:
        txt = "; ".join(f"{nb} at {db * 1e3:.3g} mm arrives at {tb * 1e6:.4g} µs, not after "
                        f"{na_} at {da * 1e3:.3g} mm ({ta * 1e6:.4g} µs)"
                        for na_, da, ta, nb, db, tb in bad)
        return {"error": f"first-arrival times do not increase with distance from the wall: "
                         f"{txt}"}
    from . import fits
    try:
        f = fits.line(np.asarray(t)[order], np.asarray(d)[order])
    except fits.FitError as e:
        return {"not_available": str(e)}
    return {"speed_m_s": f["slope"], "r2": f["r2"], "n_points": f["n_points"]}
