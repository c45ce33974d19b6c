"""Ring cracks frame by frame: the crack-orientation measure at every saved frame.

Diagnosis of studies/validation/notes.md §45 (Table 3's case 5: "some small ring cracks
(spalling)").  The report measures ring arcs and failed rings once, at the last frame
(mpipd.post.crack_orientation.measure on the three crack sections); a ring that forms and
is later overrun by radial damage does not show there.  The report now carries the same
measure at every frame (mpipd.post.analysis.ring_history); this script prints it from
--from-us on, for a run file whose report predates it: per frame and section, the number
of ring arcs, their total length and radii, and the failed rings.

    mpirun -n 1 python studies/diagnoses/ring_history.py RUN.h5 [--from-us 8]
"""
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))
sys.path.insert(0, str(Path(__file__).resolve().parent))
from diag_run import open_with_option  # noqa: E402

from mpipd.post import crack_orientation, cracks  # noqa: E402
from mpipd.post.analysis import crack_sections, ring_history  # noqa: E402


def main():
    args, run, model = open_with_option("ring_history.py", "--from-us", 8.0)
    frames = [k for k in range(run.frames) if run.time[k] * 1e6 >= args.from_us - 1e-9]
    data = crack_sections(run, model, [("damage", k) for k in frames])
    last = run.frames - 1
    crushed = {}
    for name, sec in data.items():          # the report's rule: arcs in the crushed zone left out
        failed, _ = cracks.failed_points(sec, last)
        crushed[name] = cracks.crushed_zone(sec["x"], sec["y"], failed, model.center, sec["h"],
                                            model.r_wall, model.r_out)["r_c_mm"]
    h = ring_history(data, model, frames, run.time, crushed)
    print(f"# {args.run_file}: {model.scene_name} at {run.attr('git_commit', 'unknown')}; "
          f"ring arcs (chains of circumferential failed points >= "
          f"{crack_orientation.RING_MIN_HORIZONS:g} horizons long, beyond each section's "
          f"crushed zone at the last frame: r > "
          + ", ".join(f"{r:.1f}" for r in crushed.values()) + " mm) and failed rings per frame\n")
    print("t (us)  section  ring arcs  total length (mm)  arc radii (mm)  failed rings r (mm)")
    for i, t in enumerate(h["t_us"]):
        for name, rows in h["sections"].items():
            o = rows[i]
            radii = ", ".join(f"{r:.0f}" for r in o["radii_mm"]) or "-"
            rings = ", ".join(f"{a:.1f}-{b:.1f}" for a, b in o["failed_rings_mm"]) or "-"
            print(f"{t:6.2f}  {name}  {o['ring_arcs']}  "
                  f"{o['ring_arc_length_mm']:.1f}  {radii}  {rings}")
    g = h["largest"]
    print(f"\nlargest mean length over the sections: {g['length_mm']:.1f} mm at {g['t_us']:.2f} us")


if __name__ == "__main__":
    main()
