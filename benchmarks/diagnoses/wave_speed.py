"""First-arrival wave speed of a borehole-pressure run against the closed form.

Diagnosis of docs/validation_notes.md ("first-arrival wave speed").  For each run
file (a scene like ``wave_ring_elastic.toml``: an elastic rock ring, a
``borehole_pressure`` pulse, probes A-C), prints the arrival times and the
first-arrival speed at each threshold fraction of ``postprocess.arrivals.STUDY``,
and the peak-arrival speed, beside the same measures applied to the exact
plane-strain response of an infinite elastic solid with a cylindrical cavity of the
wall radius under the same pressure history:

    u_r(r, w) = A(w) H1(k r),   k = w / c_P,   c_P = sqrt((lam + 2 mu) / rho)
    sigma_rr = (lam + 2 mu) du/dr + lam u / r,   sigma_rr(a, w) = -P(w)

(H1 the outgoing Hankel function of the second kind for e^{i w t}; the static term
sigma_rr = -p a^2 / r^2 at w = 0; Achenbach, *Wave Propagation in Elastic Solids*,
1973, §4.7 and §7.2), synthesised by FFT over a window 30x the run's length so that
the periodic images do not reach the record.  The continuum's front travels at c_P,
so its first-arrival speed is c_P at every fraction; what the runs show beyond that
is the discretisation.

    python benchmarks/diagnoses/wave_speed.py RUN.h5 [RUN.h5 ...]
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import h5py
import numpy as np
from scipy.special import h2vp, hankel2

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))

from mpipd.scene import parse                      # noqa: E402
from postprocess import arrivals                   # noqa: E402
from postprocess.model import split_scene_text     # noqa: E402

PROBES = ("A", "B", "C", "D", "E", "F", "G")


def closed_form(t, r, a, load, rho, K, G, window=30.0):
    """-sigma_rr(r, t) of the cavity problem for the load's pressure history (Pa)."""
    lam, M = K - 2.0 * G / 3.0, K + 4.0 * G / 3.0
    c = np.sqrt(M / rho)
    dt = t[1] - t[0]
    n = 1 << int(np.ceil(np.log2(window * len(t))))
    tt = np.arange(n) * dt
    P = np.fft.rfft([load.value(x) for x in tt])
    w = 2.0 * np.pi * np.fft.rfftfreq(n, dt)
    k = w[1:] / c

    def srr(rr):
        return M * k * h2vp(1, k * rr) + lam * hankel2(1, k * rr) / rr
    S = np.zeros_like(P)
    S[1:] = -P[1:] * srr(r) / srr(a)
    S[0] = -P[0] * (a / r) ** 2
    return -np.fft.irfft(S, n)[: len(t)], c


def measures(names, d, recs):
    out = {}
    for f in arrivals.STUDY:
        ta = [arrivals.first_arrival(*recs[n], f).get("t_s", np.nan) for n in names]
        out[f] = arrivals.speed(names, d, ta).get("speed_m_s", np.nan)
    tp = [recs[n][0][int(np.argmax(recs[n][1]))] for n in names]
    out["peak"] = float(np.polyfit(tp, d, 1)[0])
    out["t10"] = [arrivals.first_arrival(*recs[n], 0.1).get("t_s", np.nan) * 1e6 for n in names]
    out["peaks"] = [float(np.max(recs[n][1])) / 1e6 for n in names]
    out["n"] = -float(np.polyfit(np.log(d), np.log(out["peaks"]), 1)[0])
    return out


def one(path):
    with h5py.File(path, "r") as f:
        head, sets = split_scene_text(f.attrs["scene"])
        scene = parse(head, str(path), sets)
        x = f["geometry/x"][...]
        recs, names, r = {}, [], []
        for n in PROBES:
            if n not in f.get("probes", {}):
                continue
            g = f["probes"][n]
            t, s = g["t"][...], g["sigma_rr"][...]
            keep = np.isfinite(t)
            recs[n] = (t[keep], -s[keep])
            names.append(n)
            r.append(float(np.hypot(*x[int(g.attrs["gid"])][:2])))
    load = next(ld for ld in scene.loads if type(ld).__name__ == "BoreholePressure")
    rock = scene.parts[0]
    mat = scene.materials[rock.material]
    a = load.radius
    d = np.asarray(r) - a
    exact = {}
    for n, rr in zip(names, r):
        y, c = closed_form(recs[n][0], rr, a, load, mat.density, mat.bulk_modulus,
                           mat.shear_modulus)
        exact[n] = (recs[n][0], y)
    return rock.dx, names, d, measures(names, d, recs), measures(names, d, exact), c


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("runs", nargs="+")
    args = ap.parse_args(argv)
    cols = [f"{f * 100:g} %" for f in arrivals.STUDY] + ["peak arrivals", "peak −σ_rr (MPa)", "n"]
    print("Speeds (m/s) from the first arrivals at each fraction of the probe's peak, and "
          "from the peak arrivals; the peaks and the exponent n of peak = C d^-n.")
    print()
    print("| run | rock dx (mm) | probes | 10 % arrivals (µs) | " + " | ".join(cols) + " |")
    print("|---|---|---|---|" + "---|" * len(cols))
    for p in args.runs:
        dx, names, d, run, ex, c = one(p)
        for label, m in ((p, run), (f"closed form (c_P = {c:.0f} m/s)", ex)):
            print(f"| {label} | {dx * 1e3:g} | {', '.join(names)} | "
                  + ", ".join(f"{v:.3f}" for v in m["t10"]) + " | "
                  + " | ".join(f"{m[k]:.0f}" for k in (*arrivals.STUDY, "peak")) + " | "
                  + ", ".join(f"{v:.1f}" for v in m["peaks"]) + f" | {m['n']:.2f} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
