"""What fails the rock near the borehole: the pressure each rock point held just before
it failed, by failure mode and ring, and what failed the crushed zone's points.

Diagnosis of studies/validation/notes.md §43 (the crushed zone: compression or tension?).
From a run file, serially (rank 0 of the run file's reader; run it on 1 rank):

* **The wall probe's peaks**, every step (what the wall layer carried), if it has one.
* **Crushed zone by mode** (the last frame, on the report's three crack sections):
  mpipd.post.cracks.crushed_zone with the points' failure modes — the share of JH2
  plastic (D >= 1), JH2 tensile and tension-model failures among the failed points of
  its rings.
* **Pressure before failure** (needs ``failure_mode`` and ``pressure`` at frames close
  together, e.g. ``--set output.every=4 --set 'output.fields=["pressure",
  "failure_mode","damage"]'``): for each rock point that failed, the pressure p
  (compression positive) at the last frame before the one where its failure mode is
  first set (a failed point's pressure is zeroed, so that frame holds 0); by failure
  mode and by ring of width dx from the wall, the median p, the share with p < 0 and
  the median failure time; the points beyond the last ring are summed in one row.  The
  pressure is the state up to ``output.every`` steps before the failure; points failed
  at the first frame have no state before it and are counted apart.  ``--crushed-only``
  skips this part (a run whose frames are microseconds apart).

    mpirun -n 1 python studies/diagnoses/failure_pressure.py RUN.h5 [--rings 14]
"""
import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))
sys.path.insert(0, str(Path(__file__).resolve().parent))
from diag_run import open_run  # noqa: E402

from mpipd.kernels.layout import MODE_NAMES  # noqa: E402
from mpipd.post import cracks  # noqa: E402
from mpipd.post.analysis import crack_sections  # noqa: E402


def crushed_by_mode(run, model, last):
    data = crack_sections(run, model, [("damage", last), ("failure_mode", last)])
    if not all(("failure_mode", last) in sec for sec in data.values()):
        print("no failure_mode field: no crushed zone by mode")
        return
    print(f"crushed zone at t = {run.time[last] * 1e6:.2f} us, by the failure mode of its "
          "failed points:")
    for name, sec in data.items():
        failed, _ = cracks.failed_points(sec, last)
        c = cracks.crushed_zone(sec["x"], sec["y"], failed, model.center, sec["h"],
                                model.r_wall, model.r_out, mode=sec[("failure_mode", last)])
        share = ", ".join(f"{k} {v:.3f}" for k, v in c.get("mode_share", {}).items() if v)
        print(f"  {name}: {c['extent_mm']:.2f} mm ({c['extent_borehole_radii']:.2f} R_b); "
              f"{share or 'no crushed ring'}")


def pressure_before_failure(run, model, rings):
    rock = np.flatnonzero(model.is_rock(run.geometry("part")))
    x = run.geometry("x")[rock]
    frames = run.frames
    mode = np.stack([run.field("failure_mode", k)[rock] for k in range(frames)]).astype(int)
    p = np.stack([run.field("pressure", k)[rock] for k in range(frames)])
    t = np.asarray(run.time)
    first = np.where((mode != 0).any(axis=0), (mode != 0).argmax(axis=0), -1)
    ring, _, dx = cracks.ring_index(x[:, 0], x[:, 1], model.center, model.wall_dx,
                                    model.r_wall, model.r_out)
    every = (t[1] - t[0]) * 1e6 if frames > 1 else float("nan")
    print(f"\npressure before failure: {frames} frames {every:.3g} us apart; "
          f"{len(rock)} rock points, {np.count_nonzero(first > 0)} failed after the first "
          f"frame, {np.count_nonzero(first == 0)} at it")
    for code in sorted(set(np.unique(mode[-1]).tolist()) - {0}):
        q = np.flatnonzero((first > 0) & (mode[-1] == code))
        if not len(q):
            continue
        pb = p[first[q] - 1, q]
        print(f"\n{MODE_NAMES[code]}: {len(q)} points, p before failure median "
              f"{np.median(pb) / 1e6:.1f} MPa, share p < 0 {np.mean(pb < 0):.3f}")
        print("  ring (R_b beyond the wall)  points  median p (MPa)  share p < 0  median t (us)")
        for k in range(rings + 1):
            s = q[ring[q] == k] if k < rings else q[ring[q] >= rings]
            if len(s) < 5:
                continue
            ps = p[first[s] - 1, s]
            span = (f"{k * dx / model.r_wall:4.2f}-{(k + 1) * dx / model.r_wall:4.2f}" if k < rings
                    else f"beyond {k * dx / model.r_wall:4.2f}")
            print(f"  {span}  {len(s):6d}  {np.median(ps) / 1e6:9.1f}  {np.mean(ps < 0):10.3f}"
                  f"  {np.median(t[first[s]]) * 1e6:9.2f}")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("run_file")
    ap.add_argument("--rings", type=int, default=14)
    ap.add_argument("--crushed-only", action="store_true")
    args = ap.parse_args()
    run, model = open_run(args.run_file, "failure_pressure.py")
    commit = run.attr("git_commit", "unknown")
    print(f"# {args.run_file}: {model.scene_name} at {commit}, overrides "
          f"{' '.join(model.overrides) or 'none'}\n")
    crushed_by_mode(run, model, run.frames - 1)
    if "probes/wall" in run.f:
        srr, p, vr = (run.f[f"probes/wall/{k}"][()] for k in ("sigma_rr", "p", "v_r"))
        print(f"  probe wall (every step): peak -sigma_rr {-srr.min() / 1e6:.1f} MPa, "
              f"peak pressure {p.max() / 1e6:.1f} MPa, peak |v_r| {np.abs(vr).max():.2f} m/s")
    if args.crushed_only:
        return
    if run.has_field("pressure") and run.has_field("failure_mode"):
        pressure_before_failure(run, model, args.rings)
    else:
        print("\nno pressure or failure_mode field: no pressure before failure")


if __name__ == "__main__":
    main()
