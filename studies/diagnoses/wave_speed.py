"""First-arrival wave speed of a borehole-pressure run against the closed form.

Diagnosis of studies/validation/notes.md ("first-arrival wave speed").  For each run
file (a scene like ``wave_ring_elastic.toml``: an elastic rock ring, a
``borehole_pressure`` pulse, probes A-C), prints the arrival times and the
first-arrival speed at each threshold fraction of ``mpipd.post.arrivals.STUDY``,
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

    python studies/diagnoses/wave_speed.py RUN.h5 [RUN.h5 ...]
    python studies/diagnoses/wave_speed.py --study [--out FILE.md]

``--study`` runs the variants of ``VARIANTS`` whose run file is missing (under
mpirun, ``--ranks``, into ``runs/diag/<name>``) and writes the table of all of them
(``make diagnoses`` writes studies/diagnoses/out/wave_ring_elastic.md).
"""
from __future__ import annotations

import argparse
import os
import subprocess
import sys
from pathlib import Path

import h5py
import numpy as np
from scipy.special import h2vp, hankel2

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))

from mpipd.input.loads import BoreholePressure  # noqa: E402
from mpipd.input.scene import parse  # noqa: E402
from mpipd.output.writer import short_commit  # noqa: E402
from mpipd.post import arrivals  # noqa: E402
from mpipd.post.model import split_scene_text  # noqa: E402

PROBES = ("A", "B", "C", "D", "E", "F", "G")
HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
# name -> (scene file, --set overrides): the horizon at fixed dx, dx at a fixed
# horizon factor, and the larger ring for the peaks and n
VARIANTS = {
    "elastic_dx2.0": ("wave_ring_elastic.toml", ["parts.0.dx=2.0e-3"]),
    "elastic_dx1.5": ("wave_ring_elastic.toml", ["parts.0.dx=1.5e-3"]),
    "elastic_dx1.0": ("wave_ring_elastic.toml", []),
    "elastic_m2": ("wave_ring_elastic.toml", ["parts.0.horizon_factor=2.0"]),
    "elastic_m4": ("wave_ring_elastic.toml", ["parts.0.horizon_factor=4.0"]),
    "elastic_r60": ("wave_ring_elastic_r60.toml", []),
}


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
        if f == arrivals.FRACTION:
            out["t10"] = [x * 1e6 for x in ta]
    tp = [recs[n][0][int(np.argmax(recs[n][1]))] for n in names]
    out["peak"] = float(np.polyfit(tp, d, 1)[0])
    out["peaks"] = [float(np.max(recs[n][1])) / 1e6 for n in names]
    out["n"] = -float(np.polyfit(np.log(d), np.log(out["peaks"]), 1)[0])
    return out


def one(path):
    with h5py.File(path, "r") as f:
        head, sets = split_scene_text(f.attrs["scene"])
        scene = parse(head, str(path), sets)
        commit = short_commit(f.attrs.get("git_commit", "unknown"))
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
    load = next(ld for ld in scene.loads if isinstance(ld, BoreholePressure))
    rock = scene.parts[0]
    mat = scene.materials[rock.material]
    a = load.radius
    d = np.asarray(r) - a
    exact = {}
    for n, rr in zip(names, r):
        y, c = closed_form(recs[n][0], rr, a, load, mat.density, mat.bulk_modulus,
                           mat.shear_modulus)
        exact[n] = (recs[n][0], y)
    return rock.dx, names, d, measures(names, d, recs), measures(names, d, exact), c, commit


def run_missing(out_root: Path, mpirun: str, ranks: int) -> list[str]:
    """Run every variant whose run file is missing; their run files, in order."""
    files = []
    for name, (scene, sets) in VARIANTS.items():
        out = out_root / name
        if not (out / "run.h5").is_file():
            cmd = [*mpirun.split(), "-n", str(ranks), str(Path(sys.executable).parent / "mpipd"), "run",
                   str(HERE / scene), "--out", str(out)]
            for s in sets:
                cmd += ["--set", s]
            print(" ".join(cmd), flush=True)
            with open(out_root / f"{name}.log", "w") as log:
                subprocess.run(cmd, check=True, stdout=log, stderr=subprocess.STDOUT,
                               env={**os.environ, "OMP_NUM_THREADS": "1"})
        files.append(str(out / "run.h5"))
    return files


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("runs", nargs="*")
    ap.add_argument("--study", action="store_true", help="run the missing VARIANTS, table of all")
    ap.add_argument("--runs-dir", default=str(ROOT / "runs" / "diag"))
    ap.add_argument("--mpirun", default="mpirun")
    ap.add_argument("--ranks", type=int, default=2)
    ap.add_argument("--out", help="write the table (markdown) here as well")
    args = ap.parse_args(argv)
    if args.study:
        Path(args.runs_dir).mkdir(parents=True, exist_ok=True)
        args.runs = run_missing(Path(args.runs_dir), args.mpirun, args.ranks)
    if not args.runs:
        ap.error("give run files or --study")
    lines = table(args.runs)
    print("\n".join(lines))
    if args.out:
        commit = subprocess.run(["git", "-C", str(ROOT), "rev-parse", "--short=12", "HEAD"],
                                capture_output=True, text=True).stdout.strip() or "unknown"
        head = ["# Diagnosis: the first-arrival wave speed and the peaks of an elastic ring", "",
                f"Written by `python studies/diagnoses/wave_speed.py {' '.join(argv or sys.argv[1:])}` "
                f"at commit {commit}, from the run files named in the first column (scenes "
                "`studies/diagnoses/wave_ring_elastic*.toml`, overrides in `VARIANTS`).  "
                "Each run's row is followed by the closed form (plane strain, infinite medium) "
                "for the same probe points and load.", ""]
        Path(args.out).parent.mkdir(parents=True, exist_ok=True)
        Path(args.out).write_text("\n".join(head + lines) + "\n")
    return 0


def table(runs) -> list[str]:
    """Markdown rows: each run, then the closed form for its probe points and load."""
    cols = [f"{f * 100:g} %" for f in arrivals.STUDY] + [
        "peak arrivals", "peak −σ_rr (MPa)", "n", "10 % lead on the closed form (µs)"]
    L = ["Speeds (m/s) from the first arrivals at each fraction of the probe's own peak "
         "−σ_rr, and from the peak arrivals; the peaks, the exponent n of peak = C d^-n, and "
         "how much earlier than the closed form each probe's 10 % arrival comes.", "",
         "| run | rock dx (mm) | probes (d, mm) | 10 % arrivals (µs) | " + " | ".join(cols) + " |",
         "|---|---|---|---|" + "---|" * len(cols)]
    for p in runs:
        dx, names, d, run, ex, c, commit = one(p)
        try:
            shown = Path(p).resolve().relative_to(ROOT)
        except ValueError:
            shown = p
        lead = ", ".join(f"{a - b:.3f}" for a, b in zip(ex["t10"], run["t10"]))
        for label, m, extra in ((f"`{shown}` (at {commit})", run, lead), (f"closed form (c_P = {c:.0f} m/s)", ex, "")):
            L.append(f"| {label} | {dx * 1e3:g} | "
                     + ", ".join(f"{n} {v * 1e3:.2f}" for n, v in zip(names, d)) + " | "
                     + ", ".join(f"{v:.3f}" for v in m["t10"]) + " | "
                     + " | ".join(f"{m[k]:.0f}" for k in (*arrivals.STUDY, "peak")) + " | "
                     + ", ".join(f"{v:.1f}" for v in m["peaks"]) + f" | {m['n']:.2f} | {extra} |")
    return L


if __name__ == "__main__":
    sys.exit(main())
