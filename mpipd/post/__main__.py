"""``mpirun -n N python -m mpipd.post {summary | wave-speed | fracture | report | compare |
validate} RUN.h5``

summary      points, frames, time span, energy drift (or the ledger's largest |balance|),
             peak |v| per frame
wave-speed   arrival speed of a pulse: the peak time of the cross-section mean of
             one velocity component at several stations along an axis, fitted by a
             straight line (parabolic interpolation of each peak between frames)
fracture     a PNG of the damage phi (or another scalar field) on a z section of a
             part that can fail (--part, default the rock) nearest --z (default:
             the part's middle) at a frame (default: the last); says which part
             and level, refuses a section that holds none of the part
report       report.md, report.json and figures of one run in --out (mpipd.post.report):
             for any scene, damage on named sections through the rock, failure
             modes, per charge the damaged extent and crushed zone, the energy
             ledger, the probes and the warnings; the paper's validation (figures,
             targets) when the scene is the paper's specimen, or with --paper
animate      a GIF of damage on a section through a part that can fail over the
             saved frames (matplotlib's PillowWriter)
compare      several runs side by side: compare.md/.json and the fracture patterns,
             rock energy and peak radial stress of all runs in one figure each
validate     the validation record: OUT.md with every run's provenance, one
             table of the targets (a value and verdict column per run), key figures and
             report.json copied into OUT/<case>/ (mpipd.post.validation); a run file or
             run folder is reported first

A file that is not a readable mpipd run file gives one line on stderr and exit status 2.
"""
from __future__ import annotations

import argparse
import sys

import numpy as np

from .fits import peak_time
from .reader import Run, RunFileError
from .sections import part_mask, section

AXES = {"x": 0, "y": 1, "z": 2}


class UsageError(Exception):
    """Bad options: one line, exit status 2."""


def summary(run: Run, comm) -> list[str]:
    v = run.field("v") if run.has_field("v") else None
    t = run.time
    held = run.f["time"].shape[0]
    lines = [f"points {run.n_points}  frames {run.frames}"
             + (f" (of {held}; the rest not yet written)" if held > run.frames else "")
             + f"  t {t[0]:.4e}..{t[-1]:.4e} s"]
    if run.has_energy("balance"):
        b = np.abs(run.energy("balance"))
        lines.append(f"energy ledger: largest |balance| {np.nanmax(b):.3e} (relative closure "
                     "error)")
    elif run.has_energy("total"):
        e = run.energy("total")
        lines.append(f"energy total {e[0]:.6e} -> {e[-1]:.6e} J, max drift "
                     f"{np.abs(e - e[0]).max() / abs(e[0]) if e[0] else float('nan'):.3e} "
                     "(relative)")
    if v is not None:
        local = np.sqrt((v ** 2).sum(axis=2)).max(axis=1) if v.shape[1] else np.zeros(run.frames)
        peak = run.max_array(local)
        lines.append("peak |v| per frame (m/s): " + " ".join(f"{p:.4g}" for p in peak))
    return lines


def station_means(run: Run, comm, axis: int, comp: int, stations, tol) -> np.ndarray:
    """(frames, stations) mean of v[..., comp] over points within tol of each station."""
    x = run.geometry("x")[:, axis]
    v = run.field("v")[:, :, comp]
    sums = np.zeros((run.frames, len(stations)))
    counts = np.zeros(len(stations))
    for k, s in enumerate(stations):
        m = np.abs(x - s) <= tol
        sums[:, k] = run.level_total(run.per_level(np.where(m[:, None], v.T, 0.0)))
        counts[k] = run.sum_int(int(m.sum()))
    if np.any(counts == 0):
        raise ValueError(f"no points near station(s) {[s for s, c in zip(stations, counts) if not c]}")
    return sums / counts


def wave_speed(run: Run, comm, axis: str, component: str, stations, tol) -> tuple[float, list]:
    """Slope of the stations against the peak times of their means (:func:`fits.peak_time`);
    a peak at the first or last frame is refused (its time is not known)."""
    means = station_means(run, comm, AXES[axis], AXES[component], stations, tol)
    arrivals = []
    for k in range(len(stations)):
        t, _, interior = peak_time(run.time, means[:, k])
        if not interior:
            raise ValueError("the peak is at the first or last frame: the run is too short "
                             "or the station too far")
        arrivals.append(t)
    speed = float(np.polyfit(arrivals, stations, 1)[0])
    return speed, arrivals


def frame_index(run: Run, frame: int) -> int:
    """``--frame`` as an index into the written frames (negative from the end);
    one outside them is refused."""
    if not -run.frames <= frame < run.frames:
        raise ValueError(f"--frame {frame}: the run file holds {run.frames} frame(s) "
                         f"(0..{run.frames - 1}, or -{run.frames}..-1 from the end)")
    return frame % run.frames


def check_z(run: Run, comm, z: float | None) -> None:
    """A section height more than a lattice spacing beyond the body is refused."""
    if z is None:
        return
    x = run.geometry("x")
    zmin = run.min(x[:, 2].min() if len(x) else np.inf)
    zmax = run.max(x[:, 2].max() if len(x) else -np.inf)
    vol = run.geometry("volume")
    dx = float(np.cbrt(run.max(vol.max() if len(vol) else 0.0)))
    if not zmin - dx <= z <= zmax + dx:
        raise ValueError(f"--z {z:g} m is outside the body (its points span z = {zmin:g}.."
                         f"{zmax:g} m)")


def check_png_out(out: str) -> None:
    from pathlib import Path
    p = Path(out)
    if p.is_dir():
        raise ValueError(f"--out {out} is a directory (give the PNG's path)")
    if not p.resolve().parent.is_dir():
        raise ValueError(f"--out {out}: no directory {p.resolve().parent}")


def failing_part(run) -> str:
    """The part a damage picture shows by default: the rock (the part named ``rock``,
    else of a ``jh2`` material, else the largest: :func:`mpipd.post.model.load_model`),
    by its name without a zone suffix."""
    from .model import base_name, load_model
    m = load_model(run)
    return base_name(m.part_names[m.rock])


def fracture_png(run: Run, comm, out, field="damage", frame=-1, z=None, part=None) -> list[str]:
    k = frame_index(run, frame)
    check_z(run, comm, z)
    check_png_out(out)
    if run.has_field(field) and run.f["fields"][field].ndim > 2:
        raise ValueError(f"field {field!r} is not a scalar")
    sec, part = part_section(run, field, k, z, part)
    if comm.Get_rank() != 0:
        return []
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6, 5.2), dpi=120)
    draw_section(ax, fig, sec, field, run.time[k], part)
    fig.tight_layout()
    fig.savefig(out)
    plt.close(fig)
    return [f"wrote {out}: {field} of part {part!r} on its z level {sec.z * 1e3:.4g} mm "
            f"({len(sec.x)} points on the section)"]


def part_section(run, field, k, z, part):
    """The section of ``part`` (default :func:`failing_part`): its level nearest ``z``
    (default its middle).  With ``z``, the level is the nearest of the whole model's; one
    that holds none of the part's points is refused (ValueError naming the part's
    nearest level)."""
    part = part or failing_part(run)
    mine = part_mask(run, part)
    if z is not None:
        allz = run.comm.allgather(np.unique(run.z_level))
        levels = np.unique(np.concatenate(allz)) if allz else np.zeros(0)
        zlev = float(levels[np.argmin(np.abs(levels - z))])
        own = run.comm.allgather(np.unique(run.z_level[mine]))
        plev = np.unique(np.concatenate(own))
        if not np.any(plev == zlev):
            near = float(plev[np.argmin(np.abs(plev - z))])
            raise ValueError(f"the section at z = {zlev * 1e3:.4g} mm (the level nearest --z "
                             f"{z:g}) holds no point of part {part!r}: its nearest level is "
                             f"z = {near:g} m (give --z {near:g}, or --part)")
        z = zlev
    return section(run, field, k, z, part=part), part


def draw_section(ax, fig, sec, field, t, part):
    xs, ys, vs = sec.x, sec.y, sec.values
    size = max(1.0, 2.2e4 / max(len(xs), 1))
    im = ax.scatter(xs * 1e3, ys * 1e3, c=vs, s=size, marker="s", cmap="inferno",
                    vmin=0.0, vmax=max(1.0, float(vs.max())) if field == "damage" else None)
    ax.set_aspect("equal")
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("y (mm)")
    ax.set_title(f"{field} of {part} at t = {t * 1e6:.2f} us, z = {sec.z * 1e3:.2f} mm")
    if fig is not None:
        fig.colorbar(im, ax=ax, shrink=0.85)
    return im


def animate(run: Run, comm, out, field="damage", z=None, part=None, fps=4) -> list[str]:
    """A GIF of ``field`` on one section of a part that can fail at every saved frame."""
    from pathlib import Path
    check_z(run, comm, z)
    if Path(out).suffix.lower() != ".gif":
        raise ValueError(f"--out {out}: the animation is a GIF (give a .gif path)")
    check_png_out(out)
    secs_ = []
    for k in range(run.frames):
        sec, part = part_section(run, field, k, z, part)
        secs_.append(sec)
        z = run.comm.bcast(sec.z if sec is not None else None, root=0)
    if comm.Get_rank() != 0:
        return []
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.animation import PillowWriter
    fig, ax = plt.subplots(figsize=(6, 5.2), dpi=100)
    writer = PillowWriter(fps=fps)
    with writer.saving(fig, out, dpi=100):
        for k, sec in enumerate(secs_):
            ax.clear()
            draw_section(ax, fig if k == 0 else None, sec, field, run.time[k], part)
            fig.tight_layout()
            writer.grab_frame()
    plt.close(fig)
    return [f"wrote {out}: {field} of part {part!r} on its z level {secs_[0].z * 1e3:.4g} mm, "
            f"{len(secs_)} frames"]


def main(argv=None) -> int:
    from mpi4py import MPI
    comm = MPI.COMM_WORLD
    ap = argparse.ArgumentParser(prog="python -m mpipd.post", description=__doc__.split("\n\n")[0])
    sub = ap.add_subparsers(dest="cmd", required=True)
    s = sub.add_parser("summary")
    s.add_argument("run")
    w = sub.add_parser("wave-speed")
    w.add_argument("run")
    w.add_argument("--axis", default="x", choices=list(AXES))
    w.add_argument("--component", default="x", choices=list(AXES))
    w.add_argument("--stations", required=True, help="comma-separated positions along the axis (m)")
    w.add_argument("--tol", type=float, default=None,
                   help="half-width of a station (m); default half the lattice spacing")
    fr = sub.add_parser("fracture")
    fr.add_argument("run")
    fr.add_argument("--out", default=None, help="PNG path (default: beside the run file)")
    fr.add_argument("--field", default="damage")
    fr.add_argument("--frame", type=int, default=-1)
    fr.add_argument("--z", type=float, default=None,
                    help="section height (m): the nearest z level of the model, which must "
                         "hold points of the part (default: the part's middle level)")
    fr.add_argument("--part", default=None,
                    help="the part shown (default: the rock, the part that can fail)")
    an = sub.add_parser("animate", help="a GIF of damage over the saved frames")
    an.add_argument("run")
    an.add_argument("--out", default=None, help="GIF path (default: beside the run file)")
    an.add_argument("--field", default="damage")
    an.add_argument("--z", type=float, default=None, help="section height (m), as fracture's")
    an.add_argument("--part", default=None, help="the part shown (default: the rock)")
    an.add_argument("--fps", type=float, default=4.0, help="frames per second (default 4)")
    rp = sub.add_parser("report", help="figures and report.md/report.json of one run")
    rp.add_argument("run")
    rp.add_argument("--out", default=None, help="directory (default: RUN's folder /report)")
    pp = rp.add_mutually_exclusive_group()
    pp.add_argument("--paper", dest="paper", action="store_true", default=None,
                    help="the paper's validation report whatever the scene")
    pp.add_argument("--no-paper", dest="paper", action="store_false",
                    help="the report of any scene, even on the paper's specimen")
    rp.add_argument("--fragments", action="store_true",
                    help="also the fragments of the last frame (OUT/fragments)")
    rp.add_argument("--times", default=None,
                    help="comma-separated times (us) for the fracture pattern (default: four "
                         "saved frames evenly spaced, ending at the last)")
    cp = sub.add_parser("compare", help="several runs side by side")
    cp.add_argument("runs", nargs="+")
    cp.add_argument("--out", default="compare", help="directory (default: ./compare)")
    cp.add_argument("--labels", default=None, help="comma-separated run labels")
    cp.add_argument("--view", default="detonation-face",
                    choices=["detonation-face", "mid", "far-face"],
                    help="section of the fracture figure (Figs. 19, 22 view the detonation side)")
    va = sub.add_parser("validate", help="the validation record of several runs")
    va.add_argument("runs", nargs="+", metavar="RUNDIR_OR_REPORT",
                    help="a report directory (report.json + figures), a run folder or run.h5 "
                         "(reported first, into report/ beside the run file)")
    va.add_argument("--out", default="studies/validation/record",
                    help="directory of the per-run files; the record is OUT.md beside it "
                         "(default: studies/validation/record -> studies/validation/record.md)")
    va.add_argument("--notes", default=None, help="hand-written diagnoses (markdown), inserted "
                    "verbatim under 'Diagnoses'")
    va.add_argument("--base", default=None, metavar="CASE",
                    help="the row the record's Summary table shows (a run folder's name; "
                         "default: the first run)")
    va.add_argument("--check", action="store_true",
                    help="only check that every input exists (exit 2 naming what is missing)")
    fg = sub.add_parser("fragments", help="fragments of a frame and the size distribution")
    fg.add_argument("run")
    fg.add_argument("--out", default=None, help="directory (default: RUN's folder /fragments)")
    fg.add_argument("--frame", type=int, default=-1, help="frame index (default: the last)")
    fg.add_argument("--parts", default=None,
                    help="comma-separated parts to analyse (default: the rock, jh2 parts)")
    fg.add_argument("--min-points", type=int, default=8,
                    help="smaller components are fines (default 8 = 2 x 2 x 2 points)")
    fg.add_argument("--damage-threshold", type=float, default=None,
                    help="also cut bonds whose two ends both have damage above this")
    fg.add_argument("--z", type=float, default=None, help="height of the section figure (m)")
    bn = sub.add_parser("bench", help="fragmentation, overbreak and PPV of bench blasts")
    bn.add_argument("runs", nargs="+")
    bn.add_argument("--out", default="bench", help="directory (default: ./bench)")
    bn.add_argument("--labels", default=None, help="comma-separated run labels")
    args = ap.parse_args(argv)
    args.argv = list(sys.argv[1:] if argv is None else argv)
    if args.cmd in ("report", "compare", "validate", "fragments", "bench"):
        return _guarded(comm, _analysis_cmd, args, comm)
    try:
        run = Run(args.run, comm)
    except RunFileError as e:
        if comm.Get_rank() == 0:
            print(f"mpipd.post: error: {e}", file=sys.stderr)
        return 2
    try:
        if args.cmd == "summary":
            lines = summary(run, comm)
        elif args.cmd == "fracture":
            from pathlib import Path
            out = args.out or str(Path(args.run).with_name(f"{args.field}.png"))
            lines = fracture_png(run, comm, out, args.field, args.frame, args.z, args.part)
        elif args.cmd == "animate":
            from pathlib import Path
            out = args.out or str(Path(args.run).with_name(f"{args.field}.gif"))
            lines = animate(run, comm, out, args.field, args.z, args.part, args.fps)
        else:
            stations = [float(v) for v in args.stations.split(",")]
            tol = args.tol
            if tol is None:
                tol = 0.5 * float(np.cbrt(run.f["geometry"]["volume"][0])) + 1e-12
            speed, arrivals = wave_speed(run, comm, args.axis, args.component, stations, tol)
            lines = [f"station {s:.5g} m: peak at {a:.6e} s" for s, a in zip(stations, arrivals)]
            lines.append(f"wave speed {speed:.2f} m/s")
    except (KeyError, ValueError) as e:
        if comm.Get_rank() == 0:
            print(f"mpipd.post: error: {e}", file=sys.stderr)
        return 2
    finally:
        run.close()
    if comm.Get_rank() == 0:
        print("\n".join(lines))
    return 0


def _analysis_cmd(args, comm) -> list[str]:
    from pathlib import Path
    if args.cmd == "bench":
        from .bench import make_bench
        labels = args.labels.split(",") if args.labels else [Path(r).parent.name
                                                              for r in args.runs]
        if len(labels) != len(args.runs) or len(set(labels)) != len(labels):
            raise UsageError("--labels: one distinct label per run")
        return make_bench(args.runs, labels, args.out, comm)
    if args.cmd == "fragments":
        from .fragment_report import make_fragments
        if args.min_points < 1:
            raise UsageError(f"--min-points must be >= 1 (got {args.min_points})")
        out = args.out or str(Path(args.run).resolve().parent / "fragments")
        parts = args.parts.split(",") if args.parts else None
        return make_fragments(args.run, out, comm, args.frame, parts, args.min_points,
                              args.damage_threshold, args.z)
    if args.cmd == "report":
        from .report import make_report
        out = args.out or str(Path(args.run).resolve().parent / "report")
        if Path(out).exists() and not Path(out).is_dir():
            raise UsageError(f"--out {out} exists and is not a directory")
        times = [float(t) for t in args.times.split(",")] if args.times else None
        return make_report(args.run, out, comm, times, args.paper, args.fragments)
    if args.cmd == "validate":
        from .validation import InputError, make_validation
        try:
            return make_validation(args.runs, args.out, comm, args.notes, args.argv, args.check,
                                   args.base)
        except InputError as e:
            raise UsageError(str(e)) from None
    from .compare import make_compare
    labels = args.labels.split(",") if args.labels else None
    if labels and len(labels) != len(args.runs):
        raise UsageError(f"--labels gives {len(labels)} labels for {len(args.runs)} runs")
    return make_compare(args.runs, args.out, comm, labels, args.view)


def _guarded(comm, fn, *args) -> int:
    """Bad input (a file that is not a run, bad options): one line, exit 2 on every rank.
    Anything else: the traceback, and the whole job is aborted so no rank hangs."""
    try:
        lines = fn(*args)
    except (RunFileError, UsageError) as e:
        if comm.Get_rank() == 0:
            print(f"mpipd.post: error: {' '.join(str(e).split())}", file=sys.stderr)
        return 2
    except Exception:                                     # noqa: BLE001
        import traceback
        traceback.print_exc()
        sys.stderr.flush()
        if comm.Get_size() > 1:
            comm.Abort(1)
        return 1
    if comm.Get_rank() == 0 and lines:
        print("\n".join(lines))
    return 0


if __name__ == "__main__":
    sys.exit(main())
