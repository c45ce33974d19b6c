"""Arrival of the stress wave at a probe, from its every-step record of -sigma_rr.

* First arrival: the first time -sigma_rr reaches the threshold, linearly
  interpolated between the sample below and the sample at or above it.  A record
  already above the threshold at its first sample has no arrival.
* First pulse: the samples from the arrival until -sigma_rr falls below half of its
  running maximum since the arrival (or the end of the record).  If the global peak
  lies after that, the peak belongs to a later pulse (a reflection, or the crack
  that reaches the probe) and the paper's peak-arrival time is not the arrival of
  the direct wave.
* Threshold: ``FRACTION`` = 10 % of the peak of the **first pulse**, so that nothing
  that happens after the direct wave has passed can move its arrival.  Arrival and
  first pulse define each other; they are found as a fixed point, starting from the
  record's peak: thr = f max(y) gives an arrival and a first pulse, and while
  f x (that pulse's peak) is below thr, thr takes that value and the arrival is
  sought again.  thr only falls and the arrival only moves earlier, so it ends
  after at most as many passes as there are samples (two or three in practice).
  Up to 2026-12 the threshold was 10 % of the record's peak: at ``blast_demo``'s
  probe C a compressive spike at 18 µs, after the direct wave, then set the
  threshold and moved the arrival by 0.19 µs (docs/multirate.md).
* Sample times: a probe's stress is the state of its point at ``t_state``
  (mpipd.output.probes): every step in the fine class, but under multi-rate a point
  of class k holds the stress of its last update for 2^k - 1 more steps.  Timing that
  staircase at the recording steps would put the arrival up to (2^k - 1) dt late;
  :func:`state_samples` keeps one sample per state, at the time it was taken.
* A probe whose point fails during its first pulse has no arrival: its record then
  ends at the failure (a failed point carries no stress), so the pulse's "peak" is
  the stress at which the point broke, not the wave's, and a threshold taken from it
  is not a phase of the wave.  At ``blast_paper:dx1.2`` (ratio 4) probe A, 7 mm from
  the wall, rose for 7 µs under the borehole's pressure to 188 MPa and failed: 10 %
  of that is 21 MPa, reached at 2.61 µs, after B (10.6 mm) arrived at 2.36 µs.
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

FRACTION = 0.10              # threshold = 10 % of the first pulse's peak -sigma_rr
STUDY = (0.02, 0.05, 0.10, 0.20, 0.50)   # fractions of the threshold study
PULSE_END = 0.5              # the first pulse ends below half its running maximum
THRESHOLD_TEXT = ("10 % of the peak −σ_rr of each probe's first pulse (not of a later one), "
                  "linearly interpolated")


def first_arrival(t, y, fraction: float = FRACTION, t_failed: float | None = None) -> dict:
    """Arrival of the compressive pulse ``y`` = -sigma_rr (Pa) sampled at ``t`` (s), at
    ``fraction`` of its first pulse's peak; ``t_failed``: the time (s) from which the
    probe's point has failed (None: it never fails)."""
    t, y = np.asarray(t, float), np.asarray(y, float)
    if len(y) < 2 or not np.isfinite(y).any():
        return {"not_available": "no samples"}
    kp = int(np.nanargmax(y))
    peak = float(y[kp])
    if not peak > 0:
        return {"not_available": "no compressive pulse (−σ_rr never positive)"}
    thr = fraction * peak
    while True:
        k = int(np.argmax(y >= thr))
        if k == 0:
            return {"not_available": "−σ_rr is at or above the threshold at the first sample"}
        end = _pulse_end(y, k)
        first_peak = float(np.nanmax(y[k:end + 1]))
        if not fraction * first_peak < thr:
            break
        thr = fraction * first_peak
    if t_failed is not None and t_failed <= t[end]:
        return {"not_available": f"the point failed at {t_failed * 1e6:.4g} µs, during its first "
                                 "pulse: the pulse's peak is its failure stress, not the wave's",
                "failed_in_first_pulse": True}
    y0, y1 = y[k - 1], y[k]
    ta = float(t[k - 1] + (thr - y0) / (y1 - y0) * (t[k] - t[k - 1]))
    kf = k + int(np.nanargmax(y[k:end + 1]))
    return {"t_s": ta, "threshold_Pa": thr, "peak_Pa": peak, "t_peak_s": float(t[kp]),
            "first_pulse_end_s": float(t[end]), "first_pulse_peak_Pa": first_peak,
            "t_first_pulse_peak_s": float(t[kf]),
            "first_pulse_complete": end < len(y) - 1, "peak_in_first_pulse": kp <= end}


def _pulse_end(y, k: int) -> int:
    """Index where the pulse starting at sample k ends: the first sample below
    ``PULSE_END`` x its running maximum since k, or the last sample."""
    run_max = np.maximum.accumulate(y[k:])
    below = np.flatnonzero(y[k:] < PULSE_END * run_max)
    return k + int(below[0]) if len(below) else len(y) - 1


def state_samples(probe: dict, y) -> tuple[np.ndarray, np.ndarray]:
    """(t_state, y) with one sample per state of the probe's point: the first record
    of each run of equal ``t_state`` (a record without ``t_state`` is taken as is)."""
    ts = np.asarray(probe.get("t_state", probe["t"]), float)
    y = np.asarray(y, float)
    if len(ts) < 2:
        return ts, y
    keep = np.concatenate(([True], ts[1:] != ts[:-1]))
    return ts[keep], y[keep]


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
