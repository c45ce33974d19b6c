"""``python -m mpipd.post fragments RUN.h5``: the fragments of a frame and the
fragment-size distribution (mpipd.post.fragments, mpipd.post.sieve).

Writes into ``--out`` (default ``<run dir>/fragments``):

* ``fragments.csv``  one row a fragment (label = its smallest gid, point count,
  volume, mass, centre, d_eq, sieve size, second-moment eigenvalues), by mass;
* ``fragments.json`` the frame, the parts analysed, the counts, the fines, the
  percentiles X20/X50/X80 (sieve size), the Rosin–Rammler and Swebrec fits;
* ``fragments_curve.png`` the mass passing curve with both fits;
* ``fragments_section.png`` the points of one z layer coloured by fragment.

The curve is over the fragments of at least ``min_points`` points; the smaller
components (failed points on their own, specks of a few points) are the *fines*,
reported as a mass fraction beside it.  Runs on any number of ranks with the
same result.
"""
from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np

from mpipd.input.probes import part_matches
from mpipd.input.scene import parse
from mpipd.output.pairs import rows_between
from mpipd.parallel.team import Team

from .fragments import Fragments, sizes
from .model import split_scene_text
from .reader import RunFileError
from .sieve import rosin_rammler, summary, swebrec


class FragmentInputError(RunFileError):
    """The run cannot give fragments (no bond record, a bad frame, unknown parts)."""


def default_parts(scene) -> list[int]:
    """The rock: the parts of jh2 materials; else every solid part."""
    gas = set(scene.gas_parts)
    rock = [k for k, q in enumerate(scene.parts)
            if scene.materials[q.material].registry_name == "jh2"]
    return rock or [k for k in range(len(scene.parts)) if k not in gas]


def make_fragments(run_path, out, comm, frame: int = -1, parts=None, min_points: int = 8,
                   damage_threshold: float | None = None, z: float | None = None) -> list[str]:
    import h5py
    team = Team(comm)
    try:
        f = h5py.File(run_path, "r", driver="mpio", comm=comm)
    except (OSError, ValueError) as e:
        raise RunFileError(f"cannot open {run_path}: {' '.join(str(e).split())}") from None
    with f:
        if "bonds" not in f or "scene" not in f.attrs:
            raise FragmentInputError(f"{run_path}: no /bonds record (a run of a scene that "
                                     "cannot fail, or written before 2026-12)")
        written = int(f.attrs["frames_written"])
        k = frame if frame >= 0 else written + frame
        if not 0 <= k < written:
            raise FragmentInputError(f"--frame {frame}: the run has {written} frame(s)")
        head, sets = split_scene_text(str(f.attrs["scene"]))
        scene = parse(head, "run.h5 scene", sets)
        names = [q.name for q in scene.parts]
        if parts:
            chosen = [i for i, nm in enumerate(names) if any(part_matches(w, nm) for w in parts)]
            missing = [w for w in parts if not any(part_matches(w, nm) for nm in names)]
            if missing:
                raise FragmentInputError(f"--parts: no part {missing[0]!r} "
                                         f"(parts: {', '.join(names)})")
        else:
            chosen = default_parts(scene)
        if damage_threshold is not None and "damage" not in f["fields"]:
            raise FragmentInputError("--damage-threshold needs the damage field in the run file")
        frag = Fragments(scene, team, chosen)
        p = frag.points
        g0, g1 = frag.gid_range
        lo, hi = int(p.gid.min()), int(p.gid.max())
        off = f["bonds/offsets"]
        a, b = int(off[k]), int(off[k + 1])
        pairs = rows_between(f["bonds/broken"], a, b, lo, hi + 1)
        damage = None
        if damage_threshold is not None:
            damage = np.zeros(p.n_local)
            damage[:p.n_owned] = f["fields/damage"][k, g0:g1]
            frag.halo.exchange(damage)
        x = p.x[:p.n_owned].copy()
        moved = "u" in f["fields"]
        if moved:
            x += f["fields/u"][k, g0:g1]
        t = float(f["time"][k])
    if team.max(frag.mark_broken(pairs, damage, damage_threshold)):
        raise FragmentInputError(f"{run_path}: broken bonds in frame {k} that are not bonds "
                                 "of the run's scene")
    label = frag.labels()
    stats = frag.statistics(label, x)
    section = _section(frag, label, z)
    if not team.root:
        return []
    return _write(Path(out), stats, section, {
        "run": str(run_path), "frame": k, "t_us": t * 1e6, "parts": [names[i] for i in chosen],
        "positions": "current (x + u)" if moved else "reference (the frame has no u)",
        "min_points": min_points, "damage_threshold": damage_threshold,
        "ranks": team.size})


def _section(frag, label, z):
    """(x, y, label) of the analysed points of the layer nearest z (default: the
    analysed points' mid-height), gathered on rank 0."""
    p, team = frag.points, frag.team
    n = p.n_owned
    zs = p.x[:n, 2][label >= 0]
    zlo = team.min(float(zs.min()) if len(zs) else np.inf)
    zhi = team.max(float(zs.max()) if len(zs) else -np.inf)
    zc = 0.5 * (zlo + zhi) if z is None else z
    levels = frag.table.z[np.isin(frag.table.part, frag.parts)]     # the analysed parts' levels
    zl = float(levels[np.argmin(np.abs(levels - zc))])
    lay = frag.table.z[frag.layer]
    sel = (np.abs(lay - zl) < 1e-12) & (label >= 0)
    got = team.comm.gather((p.x[:n][sel, 0], p.x[:n][sel, 1], label[sel]), root=0)
    if not team.root:
        return None
    return (np.concatenate([g[0] for g in got]), np.concatenate([g[1] for g in got]),
            np.concatenate([g[2] for g in got]), zl)


def _write(out: Path, stats: dict, section, meta: dict) -> list[str]:
    out.mkdir(parents=True, exist_ok=True)
    sz = sizes(stats)
    big = stats["n"] >= meta["min_points"]
    total = float(stats["mass"].sum())
    doc = dict(meta)
    doc.update({"fragments": int(big.sum()), "components": int(len(stats["n"])),
                "mass_kg": total, "fines_mass_fraction": float(stats["mass"][~big].sum() / total),
                "largest_mass_fraction": float(stats["mass"].max() / total),
                "size_measure": "sieve = 2 sqrt(5 l2) (m); d_eq = (6V/pi)^(1/3)"})
    fig_names = []
    if big.sum() >= 1:
        s = summary(sz["sieve"][big], stats["mass"][big])
        x, P = s.pop("curve")
        doc.update({k: v for k, v in s.items()})
        fig_names.append(_curve_png(out / "fragments_curve.png", x, P, s, doc))
    order = np.argsort(-stats["mass"], kind="stable")
    with open(out / "fragments.csv", "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["label", "points", "volume_m3", "mass_kg", "cx_m", "cy_m", "cz_m",
                    "d_eq_m", "sieve_m", "l1_m2", "l2_m2", "l3_m2", "fine"])
        for i in order:
            w.writerow([int(stats["label"][i]), int(stats["n"][i]), f"{stats['volume'][i]:.10e}",
                        f"{stats['mass'][i]:.10e}", *(f"{v:.10e}" for v in stats["centre"][i]),
                        f"{sz['d_eq'][i]:.10e}", f"{sz['sieve'][i]:.10e}",
                        *(f"{v:.10e}" for v in sz["lambda"][i]), int(not big[i])])
    if section is not None:
        fig_names.append(_section_png(out / "fragments_section.png", section, stats, big))
    doc["figures"] = fig_names
    (out / "fragments.json").write_text(json.dumps(doc, indent=1, default=float) + "\n")
    lines = [f"fragments: {doc['fragments']} of at least {meta['min_points']} points "
             f"({doc['components']} components), frame {meta['frame']} at {meta['t_us']:.3g} us; "
             f"fines {100 * doc['fines_mass_fraction']:.2f} % of the mass, the largest "
             f"{100 * doc['largest_mass_fraction']:.1f} %"]
    if "x50" in doc:
        lines.append(f"X20 {doc['x20'] * 1e3:.3g} mm, X50 {doc['x50'] * 1e3:.3g} mm, "
                     f"X80 {doc['x80'] * 1e3:.3g} mm (sieve size)")
        rr = doc.get("rosin_rammler")
        if rr:
            lines.append(f"Rosin-Rammler: x50 {rr['x50'] * 1e3:.3g} mm, n {rr['n']:.3g} "
                         f"(R^2 {rr['r2']:.3f})")
        sw = doc.get("swebrec")
        if sw:
            lines.append(f"Swebrec: x50 {sw['x50'] * 1e3:.3g} mm, xmax {sw['xmax'] * 1e3:.3g} mm, "
                         f"b {sw['b']:.3g} (R^2 {sw['r2']:.3f})")
    lines.append(f"wrote {out}/fragments.csv, fragments.json" +
                 "".join(f", {n}" for n in fig_names))
    return lines


def _curve_png(path, x, P, s, doc):
    from .plotting import log_axes, pyplot, save
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(5.2, 3.6))
    ax.step(x * 1e3, 100 * P, where="post", color="k", lw=1.2, label="fragments")
    xs = np.geomspace(max(x[0], 1e-9), x[-1] * 1.5, 200)
    rr, sw = s.get("rosin_rammler"), s.get("swebrec")
    if rr:
        ax.plot(xs * 1e3, 100 * rosin_rammler(xs, rr["x50"], rr["n"]), "--",
                label=f"Rosin-Rammler n={rr['n']:.2f}")
    if sw:
        ax.plot(xs * 1e3, 100 * swebrec(xs, sw["x50"], sw["xmax"], sw["b"]), ":",
                label=f"Swebrec b={sw['b']:.2f}")
    ax.set_title(f"{doc['fragments']} fragments, t = {doc['t_us']:.3g} us; "
                 f"X50 {s['x50'] * 1e3:.3g} mm, X80 {s['x80'] * 1e3:.3g} mm")
    log_axes(ax, "sieve size (mm)", "mass passing (%)")
    return save(fig, path)


def _section_png(path, section, stats, big):
    from .plotting import pyplot, save
    plt = pyplot()
    xs, ys, lab, zl = section
    fig, ax = plt.subplots(figsize=(4.6, 4.4))
    fine = set(stats["label"][~big].tolist())
    is_fine = np.fromiter((v in fine for v in lab), bool, len(lab))
    ax.scatter(xs[is_fine] * 1e3, ys[is_fine] * 1e3, s=4, c="0.6", lw=0)
    rng = (lab[~is_fine] * 2654435761) % 4096 / 4096.0      # a colour per label
    ax.scatter(xs[~is_fine] * 1e3, ys[~is_fine] * 1e3, s=6, c=rng, cmap="tab20", vmin=0, vmax=1,
               lw=0)
    ax.set_aspect("equal")
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("y (mm)")
    ax.set_title(f"fragments at z = {zl * 1e3:.3g} mm (grey: fines)")
    return save(fig, path)
