"""``python -m mpipd.post bench RUN.h5 [RUN.h5 ...]``: what a blasting engineer
judges a bench blast by, for one or several runs side by side (the delay cases of
``blast_bench``).  For each run:

* **fragmentation**: the fragments of the last frame (mpipd.post.fragment_report):
  X20, X50, X80 (sieve size), the Rosin–Rammler uniformity n and the Swebrec b,
  the fines and the largest fragment as mass fractions;
* **overbreak**: how far damage reaches behind the row of holes, normal to the
  free face (d = y - y_row).  The rock between the outer holes is cut into 1-dx
  bins of d; the **overbreak depth** is the outer edge of the unbroken run of bins,
  from the row back, in each of which at least OVERBREAK_FRACTION (10 %) of the
  points are damaged (damage >= 0.5, or failed): the zone that the row broke as a
  whole, which a stray damaged point far back does not move.  Also given: the
  profile (damaged fraction per bin), the farthest damaged point, and the
  damaged fraction of all the rock behind the row;
* **vibration**: PPV against the distance d = y - y_row behind the row, from the
  running-peak speed field ``peak_speed`` (a peak over every step): per 1-dx bin
  of d, the largest peak speed among the rock points between the outer holes; and
  the fit PPV = K d^-beta over the bins beyond two hole radii.  This is the
  Holmberg–Persson law where the distance is much larger than the charge column
  (6 mm here: the column integral tends to the point-charge form K (q H)^alpha
  d^-beta); with one charge size alpha is not separable from K, so K includes it.

The holes and the free face come from the run's scene: a box rock with
``holes`` (mpipd.input.geometry.Box); the free face is the box side nearest the
row (y = lo).  Rock in an absorbing layer (mpipd.input.loads.Absorbing: the rock
mass beyond the model) is left out of overbreak and PPV: it is damped, not rock
that the blast sees as such.  Writes ``bench.md``, ``bench.json`` and two PNGs (the passing
curves and PPV against distance) into ``--out``, and each run's fragment files
into ``--out/<label>/``.
"""
from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np

from mpipd.input.scene import parse
from mpipd.output.writer import short_commit

from .fragment_report import make_fragments
from .model import split_scene_text
from .reader import Run, RunFileError

DAMAGED = 0.5
#: least damaged fraction of a 1-dx bin behind the row that still counts as overbreak
OVERBREAK_FRACTION = 0.1


def overbreak_depth(fraction: np.ndarray, counts: np.ndarray, dx: float,
                    start: int = 0) -> float:
    """Outer edge (m, from the row) of the unbroken run of bins from bin ``start`` on
    whose damaged ``fraction`` is at least OVERBREAK_FRACTION (bins without points
    are passed over; 0 if the first bin with points is below it)."""
    k = start
    last = start
    while k < len(fraction):
        if counts[k] > 0:
            if fraction[k] < OVERBREAK_FRACTION:
                break
            last = k + 1
        k += 1
    return last * dx


def _rock_box(scene):
    for k, q in enumerate(scene.parts):
        holes = getattr(q.shape, "holes", ())
        if holes and all(h.along_z for h in holes):
            return k, q
    raise RunFileError("bench: the scene has no box part with holes along z (a bench blast: "
                       "a row of vertical holes parallel to a free face)")


def bench_metrics(path, comm) -> dict:
    """Overbreak and PPV against distance of one run (collective)."""
    run = Run(path, comm)
    try:
        head, sets = split_scene_text(str(run.attr("scene")))
        scene = parse(head, "run.h5 scene", sets)
        k, rock = _rock_box(scene)
        holes = rock.shape.holes
        y_row = float(np.mean([h.center[1] for h in holes]))
        r_hole = max(h.radius for h in holes)
        xs = [h.center[0] for h in holes]
        for name in ("damage", "peak_speed"):
            if not run.has_field(name):
                raise RunFileError(f"bench: the run has no {name!r} field")
        last = run.frames - 1
        x = run.geometry("x")
        mine = run.geometry("part") == k
        dmg = run.field("damage", last)
        ppv = run.field("peak_speed", last)
        mode = run.field("failure_mode", last) if run.has_field("failure_mode") else None
        d = x[:, 1] - y_row
        layer = np.zeros(len(x), dtype=bool)
        for _, bc in scene.absorbing_layers:
            layer |= bc.damping(x, np.ones(len(x))) > 0
        behind = mine & (d > r_hole) & ~layer
        hit = behind & ((dmg >= DAMAGED) | (mode > 0 if mode is not None else False))
        depth = run.max(float(d[hit].max()) if hit.any() else 0.0)
        n_behind = run.sum_int(int(behind.sum()))
        n_hit = run.sum_int(int(hit.sum()))
        dx = rock.dx
        band = behind & (x[:, 0] >= min(xs)) & (x[:, 0] <= max(xs))
        nb = int(math.ceil((rock.shape.hi[1] - y_row) / dx)) + 1
        idx = np.clip(np.floor(d / dx).astype(int), 0, nb - 1)
        n_bin = run.sum_array(np.bincount(idx[band], minlength=nb).astype(np.int64))
        n_dmg = run.sum_array(np.bincount(idx[band & hit], minlength=nb).astype(np.int64))
        frac = n_dmg / np.maximum(n_bin, 1)
        top = np.zeros(nb)
        np.maximum.at(top, idx[band], ppv[band])
        top = run.max_array(top)
        centres = (np.arange(nb) + 0.5) * dx
        t_end = float(run.time[last])
        commit = short_commit(run.attr("git_commit", ""), 7)
        peak_gas = run.attr("peak_gas_pressure", None)
        lit = run.attr("density_at_lighting", None)
        lit = json.loads(str(lit)) if lit is not None else None
    finally:
        run.close()
    use = (centres > 2 * r_hole) & (top > 1e-3)
    fit = None
    if use.sum() >= 3:
        b, a = np.polyfit(np.log(centres[use]), np.log(top[use]), 1)
        pred = a + b * np.log(centres[use])
        res = np.log(top[use]) - pred
        ss = np.sum((np.log(top[use]) - np.log(top[use]).mean()) ** 2)
        fit = {"K": float(math.exp(a)), "beta": float(-b), "r2": float(1 - np.sum(res ** 2) / ss),
               "d_range_mm": [float(centres[use].min() * 1e3), float(centres[use].max() * 1e3)]}
    return {"commit": commit, "t_end_us": t_end * 1e6, "y_row_mm": y_row * 1e3,
            "peak_gas_pressure_GPa": None if peak_gas is None else float(peak_gas) / 1e9,
            "density_at_lighting_max": (max(v["max"] for v in lit.values()) if lit else None),
            "burden_mm": (y_row - rock.shape.lo[1]) * 1e3,
            "overbreak_mm": overbreak_depth(frac, n_bin, dx, int(r_hole // dx)) * 1e3,
            "overbreak_profile": {"d_mm": (np.arange(nb) * dx * 1e3).tolist(),
                                  "damaged_fraction": frac.tolist(),
                                  "points": np.asarray(n_bin).tolist()},
            "farthest_damaged_mm": depth * 1e3,
            "damaged_fraction_behind": n_hit / max(n_behind, 1),
            "ppv_d_mm": (centres * 1e3).tolist(), "ppv_m_s": top.tolist(), "ppv_fit": fit}


def make_bench(runs, labels, out, comm) -> list[str]:
    out = Path(out)
    # every run's bench measures first: a run that is no bench stops it before any write
    rows = {label: bench_metrics(path, comm) for path, label in zip(runs, labels)}
    for path, label in zip(runs, labels):
        make_fragments(path, out / label, comm, min_points=8)
        if comm.Get_rank() == 0:
            rows[label]["fragments"] = json.loads((out / label / "fragments.json").read_text())
    if comm.Get_rank() != 0:
        return []
    (out / "bench.json").write_text(json.dumps(rows, indent=1, default=float) + "\n")
    figs = [_curves_png(out, labels), _ppv_png(out, rows)]
    md = _table(rows, runs)
    (out / "bench.md").write_text(md + "\n" + "".join(f"![{f}]({f})\n" for f in figs))
    return [md, f"wrote {out}/bench.md, bench.json, " + ", ".join(figs)]


def _get(d, *keys):
    for k in keys:
        if not isinstance(d, dict) or d.get(k) is None:
            return None
        d = d[k]
    return d


def _table(rows, runs) -> str:
    labels = list(rows)
    spec = [("run made at commit", lambda r: r.get("commit"), "{}"),
            ("fragments (>= 8 points)", lambda r: _get(r, "fragments", "fragments"), "{}"),
            ("X20 (mm)", lambda r: _mm(_get(r, "fragments", "x20")), "{:.3g}"),
            ("X50 (mm)", lambda r: _mm(_get(r, "fragments", "x50")), "{:.3g}"),
            ("X80 (mm)", lambda r: _mm(_get(r, "fragments", "x80")), "{:.3g}"),
            ("Rosin-Rammler n", lambda r: _get(r, "fragments", "rosin_rammler", "n"), "{:.3g}"),
            ("Swebrec b", lambda r: _get(r, "fragments", "swebrec", "b"), "{:.3g}"),
            ("fines, % of the mass", lambda r: _pct(_get(r, "fragments", "fines_mass_fraction")),
             "{:.2f}"),
            ("largest fragment, % of the mass",
             lambda r: _pct(_get(r, "fragments", "largest_mass_fraction")), "{:.1f}"),
            ("overbreak depth behind the row (mm; >= 10 % of each 1-dx bin damaged)",
             lambda r: r["overbreak_mm"], "{:.3g}"),
            ("farthest damaged point behind the row (mm)",
             lambda r: r.get("farthest_damaged_mm"), "{:.3g}"),
            ("damaged fraction of the rock behind the row",
             lambda r: r["damaged_fraction_behind"], "{:.3f}"),
            ("PPV fit K (m/s at 1 m: K d^-beta)", lambda r: _get(r, "ppv_fit", "K"), "{:.3g}"),
            ("PPV fit beta", lambda r: _get(r, "ppv_fit", "beta"), "{:.3g}"),
            ("PPV fit R^2 (log)", lambda r: _get(r, "ppv_fit", "r2"), "{:.3f}"),
            ("peak gas pressure, every step (GPa)", lambda r: r.get("peak_gas_pressure_GPa"),
             "{:.3g}"),
            ("largest density of a charge when lit (x its loaded density)",
             lambda r: r.get("density_at_lighting_max"), "{:.3f}")]
    head = "| quantity | " + " | ".join(labels) + " |\n|---|" + "---|" * len(labels) + "\n"
    body = []
    for name, get, fmt in spec:
        vals = [get(rows[k]) for k in labels]
        body.append(f"| {name} | " + " | ".join("—" if v is None else fmt.format(v)
                                                  for v in vals) + " |")
    src = ", ".join(f"`{r}`" for r in runs)
    return (f"Made by `python -m mpipd.post bench` from {src} (last frame, "
            f"t = {rows[labels[0]]['t_end_us']:.3g} us; burden {rows[labels[0]]['burden_mm']:.3g} mm).\n\n"
            + head + "\n".join(body) + "\n")


def _mm(v):
    return None if v is None else v * 1e3


def _pct(v):
    return None if v is None else 100 * v


def _curves_png(out, labels):
    from .plotting import log_axes, pyplot, save
    from .sieve import passing
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(5.2, 3.6))
    for label in labels:
        rows = np.genfromtxt(out / label / "fragments.csv", delimiter=",", names=True)
        rows = np.atleast_1d(rows)
        big = rows["fine"] == 0
        if big.sum():
            x, P = passing(rows["sieve_m"][big], rows["mass_kg"][big])
            ax.step(x * 1e3, 100 * P, where="post", label=label)
    log_axes(ax, "sieve size (mm)", "mass passing (%)")
    return save(fig, out / "bench_passing.png")


def _ppv_png(out, rows):
    from .plotting import log_axes, pyplot, save
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(5.2, 3.6))
    for label, r in rows.items():
        d, v = np.array(r["ppv_d_mm"]), np.array(r["ppv_m_s"])
        keep = v > 0
        line, = ax.plot(d[keep], v[keep], ".", ms=3, label=label)
        f = r["ppv_fit"]
        if f:
            dd = np.geomspace(*f["d_range_mm"], 50)
            ax.plot(dd, f["K"] * (dd * 1e-3) ** -f["beta"], "-", lw=0.8, color=line.get_color())
    log_axes(ax, "distance behind the row (mm)", "PPV (m/s)", logy=True)
    return save(fig, out / "bench_ppv.png")
