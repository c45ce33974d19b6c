"""The angle at which a crack leaves a notch tip (Kalthoff-Winkler: about 70 degrees).

    python -m mpipd.post.crack_angle RUN.h5 [--frame -1] [--r-min 0.005] [--r-max 0.025]
                                            [--threshold 0.5] [--json OUT.json]

The notches are the scene's edge notches: each joint with a ``box``
(mpipd.input.joints) whose normal is a coordinate axis in the x-y plane and whose
patch, along the in-plane axis d perpendicular to the normal, starts at an edge of
the body and ends inside it.  The tip is that end (on the joint's plane) and the
notch direction is d, from the mouth to the tip.

The crack is the set of points on the mid-plane section (the lattice level(s)
nearest the body's mid-thickness) whose damage grew by at least ``threshold``
since the first frame (the notch's own broken bonds are there from t = 0, so they
do not count) and whose distance r from the tip lies in ``r_min`` <= r <= ``r_max``,
in front of the tip (a positive component along the notch direction or beside it:
the notch's own faces lie behind it).  Its direction is the principal axis of the
second moment about the tip, sum_j r_j r_j^T (a line through the tip), signed so
that it points away from the tip (along the mean of r_j); the angle is the one
between it and the notch direction, 0..180 degrees.  ``spread`` is the ratio of
the second to the first eigenvalue (0 for points on one line through the tip).

A window that starts a few spacings from the tip leaves out the damaged cluster
at the tip itself, whose shape is the lattice's; one that ends within about half
the notch spacing sees the crack's initial direction before it curves.
"""
from __future__ import annotations

import argparse
import json
import math
import sys
from dataclasses import asdict, dataclass

import numpy as np

from .model import split_scene_text

R_MIN, R_MAX, THRESHOLD = 0.005, 0.025, 0.5


@dataclass
class Notch:
    tip: tuple[float, float]
    direction: tuple[float, float]


@dataclass
class CrackAngle:
    tip: tuple[float, float]
    direction: tuple[float, float]      # the notch's, unit
    crack: tuple[float, float]          # the crack's, unit (NaN: no crack points)
    angle_deg: float                    # between crack and notch direction (NaN: none)
    side: float                         # +1: the crack turns to the notch direction's left
    points: int                         # damaged points in the window
    spread: float                       # second / first eigenvalue of the moment


def edge_notches(joints, x: np.ndarray) -> list[Notch]:
    """The edge notches among ``joints`` (the scene's) for a body of points ``x``."""
    lo, hi = x.min(axis=0), x.max(axis=0)
    out = []
    for j in joints:
        if j.box is None:
            continue
        n = np.asarray(j.normal, float)
        axis = int(np.argmax(np.abs(n)))
        if axis == 2 or np.count_nonzero(n) != 1:
            continue
        d_axis = 1 - axis                     # the other in-plane axis
        a = max(j.box.lo[d_axis], lo[d_axis])
        b = min(j.box.hi[d_axis], hi[d_axis])
        if not a < b:
            continue
        tip = [0.0, 0.0]
        tip[axis] = j.point[axis]
        direction = [0.0, 0.0]
        if a <= lo[d_axis] and b < hi[d_axis]:          # cut in from the low edge
            tip[d_axis], direction[d_axis] = b, 1.0
        elif b >= hi[d_axis] and a > lo[d_axis]:        # cut in from the high edge
            tip[d_axis], direction[d_axis] = a, -1.0
        else:
            continue
        out.append(Notch(tuple(tip), tuple(direction)))
    return out


def mid_plane(z: np.ndarray) -> np.ndarray:
    """The points of the lattice level(s) nearest the mid-thickness (a mask)."""
    mid = 0.5 * (z.min() + z.max())
    gap = np.abs(z - mid)
    return gap <= gap.min() + 1e-9 * max(1.0, abs(mid))


def crack_angle(xy: np.ndarray, grown: np.ndarray, notch: Notch, r_min: float = R_MIN,
                r_max: float = R_MAX) -> CrackAngle:
    """The direction in which the damaged points ``grown`` (a mask over ``xy``, the
    section's in-plane positions) leave ``notch``'s tip, within r_min..r_max of it."""
    tip = np.asarray(notch.tip, float)
    d = np.asarray(notch.direction, float)
    r = xy - tip
    dist = np.hypot(r[:, 0], r[:, 1])
    sel = grown & (dist >= r_min) & (dist <= r_max) & (r @ d > -1e-12)
    k = int(np.count_nonzero(sel))
    if k < 2:
        nan = float("nan")
        return CrackAngle(notch.tip, notch.direction, (nan, nan), nan, nan, k, nan)
    rs = r[sel]
    m = rs.T @ rs / k
    w, v = np.linalg.eigh(m)
    e = v[:, 1]
    if e @ rs.mean(axis=0) < 0:
        e = -e
    angle = math.degrees(math.acos(float(np.clip(e @ d, -1.0, 1.0))))
    side = float(np.sign(d[0] * e[1] - d[1] * e[0]))
    return CrackAngle(notch.tip, notch.direction, (float(e[0]), float(e[1])), angle, side,
                      k, float(w[0] / w[1]) if w[1] > 0 else float("nan"))


def measure(path, frame: int = -1, r_min: float = R_MIN, r_max: float = R_MAX,
            threshold: float = THRESHOLD) -> dict:
    """Every edge notch's crack angle in the run file ``path`` at ``frame`` (serial
    read: the mid-plane of a plate is small)."""
    import h5py

    from ..input.scene import parse
    with h5py.File(path, "r") as f:
        text, sets = split_scene_text(str(f.attrs["scene"]))
        scene = parse(text, str(path), sets)
        x = f["geometry"]["x"][:]
        frames = int(f.attrs["frames_written"])
        if "damage" not in f.get("fields", {}):
            raise SystemExit(f"{path}: no damage field (output.fields needs \"damage\")")
        k = frame % frames
        phi = f["fields"]["damage"][k]
        phi0 = f["fields"]["damage"][0]
        t = float(f["time"][k])
    notches = edge_notches(scene.joints, x)
    sec = mid_plane(x[:, 2])
    grown = (phi[sec] - phi0[sec]) >= threshold
    res = [crack_angle(x[sec, :2], grown, n, r_min, r_max) for n in notches]
    out = {"run": str(path), "frame": k, "t": t, "r_min": r_min, "r_max": r_max,
           "threshold": threshold, "section_z": sorted(set(np.round(x[sec, 2], 9).tolist())),
           "notches": [asdict(a) for a in res]}
    if len(res) == 2:
        out["asymmetry_deg"] = abs(res[0].angle_deg - res[1].angle_deg)
    return out


def lines(out: dict) -> list[str]:
    got = [f"crack angles at t = {out['t'] * 1e6:.2f} us (frame {out['frame']}), mid-plane "
           f"z = {', '.join(f'{z * 1e3:.3g}' for z in out['section_z'])} mm, damaged points "
           f"(growth >= {out['threshold']:g}) {out['r_min'] * 1e3:g}-{out['r_max'] * 1e3:g} mm "
           "from each tip:"]
    for a in out["notches"]:
        got.append(f"  tip ({a['tip'][0] * 1e3:.4g}, {a['tip'][1] * 1e3:.4g}) mm: "
                   f"{a['angle_deg']:.1f} deg to the notch ({a['points']} points, spread "
                   f"{a['spread']:.3f}), crack direction ({a['crack'][0]:.3f}, "
                   f"{a['crack'][1]:.3f})")
    if not out["notches"]:
        got.append("  no edge notch (a joint with a box cut in from an edge) in the scene")
    if "asymmetry_deg" in out:
        got.append(f"  the two differ by {out['asymmetry_deg']:.2f} deg")
    return got


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m mpipd.post.crack_angle",
                                 description=__doc__.split("\n\n")[0])
    ap.add_argument("run", help="run file (run.h5)")
    ap.add_argument("--frame", type=int, default=-1, help="frame (default: the last)")
    ap.add_argument("--r-min", type=float, default=R_MIN, help="window start (m)")
    ap.add_argument("--r-max", type=float, default=R_MAX, help="window end (m)")
    ap.add_argument("--threshold", type=float, default=THRESHOLD,
                    help="damage growth that makes a point cracked")
    ap.add_argument("--json", default=None, help="also write the result to this JSON file")
    args = ap.parse_args(argv)
    out = measure(args.run, args.frame, args.r_min, args.r_max, args.threshold)
    print("\n".join(lines(out)))
    if args.json:
        with open(args.json, "w") as f:
            json.dump(out, f, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
