"""Ring cracks frame by frame: the crack-orientation measure at every saved frame.

Diagnosis of docs/validation_notes.md §45 (Table 3's case 5: "some small ring cracks
(spalling)").  The report measures ring arcs and failed rings once, at the last frame
(postprocess.crack_orientation.measure on the three crack sections); a ring that forms and
is later overrun by radial damage does not show there.  This script runs the same
function, on the same sections and failure criterion, at every frame: per frame and
section, the number of ring arcs, their total length and radii, and the failed rings.

    mpirun -n 1 python benchmarks/diagnoses/ring_history.py RUN.h5 [--from-us 8]
"""
import argparse
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))
sys.path.insert(0, str(Path(__file__).resolve().parent))
from diag_run import open_run  # noqa: E402

from postprocess import crack_orientation, cracks  # noqa: E402
from postprocess.analysis import crack_sections  # noqa: E402


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("run_file")
    ap.add_argument("--from-us", type=float, default=8.0)
    args = ap.parse_args()
    run, model = open_run(args.run_file, "ring_history.py")
    frames = [k for k in range(run.frames) if run.time[k] * 1e6 >= args.from_us - 1e-9]
    data = crack_sections(run, model, [("damage", k) for k in frames])
    print(f"# {args.run_file}: {model.scene_name} at {run.attr('git_commit', 'unknown')}; "
          f"ring arcs (chains of circumferential failed points >= "
          f"{crack_orientation.RING_MIN_HORIZONS:g} horizons long) and failed rings per frame\n")
    print("t (us)  section  ring arcs  total length (mm)  arc radii (mm)  failed rings r (mm)")
    for k in frames:
        for name, sec in data.items():
            failed, _ = cracks.failed_points(sec, k)
            o = crack_orientation.measure(sec["x"], sec["y"], failed, model.center, sec["h"],
                                          model.r_wall, model.r_out, horizon=sec["link"])
            radii = ", ".join(f"{a['r_mm']:.0f}" for a in o["rings"]) or "-"
            rings = ", ".join(f"{r['r_mm'][0]:.1f}-{r['r_mm'][1]:.1f}"
                              for r in o["failed_rings"]) or "-"
            print(f"{run.time[k] * 1e6:6.2f}  {name}  {o['ring_arcs']}  "
                  f"{o['ring_arc_length_mm']:.1f}  {radii}  {rings}")


if __name__ == "__main__":
    main()
