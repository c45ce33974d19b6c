"""Where a crack-density zone's density comes from: its share inside and beyond a radius.

Diagnosis of studies/validation/notes.md §44 (zone 1 of `blast_paper:seamless`).  Fig. 12's
rule counts each failed point on a section as a crack of its own dx,

    density_k = sum over failed points i of zone k of dx_i / A_k

(mpipd.post.cracks.crack_density), so an annulus that is failed through adds
A_annulus / (dx A_k) to zone k: the finer its lattice, the more it reads.  This script
splits each zone at ``--split-mm`` (radius from the borehole's axis) on the report's three
crack sections at the last frame and prints, for each part, its failed and total points,
its dx and its share of the zone's density: the same function, fed the failed points of
one part only (the density is a sum over points).  The two shares add up to the zone's
density in report.json.

    mpirun -n 1 python studies/diagnoses/zone_split.py RUN.h5 [--split-mm 10]
"""
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))
sys.path.insert(0, str(Path(__file__).resolve().parent))
from diag_run import open_with_option  # noqa: E402

from mpipd.post import cracks  # noqa: E402
from mpipd.post.analysis import crack_sections  # noqa: E402


def split_density(x, y, failed, center, dx, r_wall, r_out, r_split):
    """Per zone: (inside r_split, beyond it) as crack_density's rows for each part's
    failed points, and the whole zone's row."""
    r = np.hypot(np.asarray(x) - center[0], np.asarray(y) - center[1])
    inner = r < r_split
    whole = cracks.crack_density(x, y, failed, center, dx, r_wall, r_out)
    parts = [cracks.crack_density(x, y, failed & m, center, dx, r_wall, r_out)
             for m in (inner, ~inner)]
    masks = cracks.zone_masks(r, cracks.per_point(dx, r), r_wall, r_out)
    return whole, parts, [(m & inner, m & ~inner) for m in masks]


def main():
    args, run, model = open_with_option("zone_split.py", "--split-mm", 10.0)
    last = run.frames - 1
    data = crack_sections(run, model, [("damage", last)])
    rs = args.split_mm * 1e-3
    print(f"# {args.run_file}: {model.scene_name} at {run.attr('git_commit', 'unknown')}; "
          f"t = {run.time[last] * 1e6:.2f} us; zones split at r = {args.split_mm:g} mm\n")
    print("section  zone  part  failed / points  dx (mm)  density share (mm/mm^2)  zone")
    for name, sec in data.items():
        failed, _ = cracks.failed_points(sec, last)
        h = cracks.per_point(sec["h"], sec["x"])
        whole, parts, masks = split_density(sec["x"], sec["y"], failed, model.center,
                                            sec["h"], model.r_wall, model.r_out, rs)
        for k, row in enumerate(whole):
            for j, label in enumerate((f"r < {args.split_mm:g}", f"r >= {args.split_mm:g}")):
                m = masks[k][j]
                if not m.any():
                    continue
                dxs = ", ".join(f"{v * 1e3:.2f}" for v in np.unique(np.round(h[m], 6)))
                print(f"{name}  {k + 1}  {label}  {np.count_nonzero(failed & m)} / "
                      f"{np.count_nonzero(m)}  {dxs}  {parts[j][k]['density_mm_per_mm2']:.3f}"
                      f"  {row['density_mm_per_mm2']:.3f}")


if __name__ == "__main__":
    main()
