"""The report of any scene (``python -m mpipd.post report`` when the scene is not the
paper's specimen, or with ``--no-paper``): report.md, report.json and figures.

* the warnings (:mod:`mpipd.post.alerts`) and the impossible values (errors);
* damage maps on sections through the rock (:func:`mpipd.post.charges.rock_levels`:
  the bottom, mid-height and top levels of the rock, rock points only) at up to four
  saved frames, and the failure modes at the last frame;
* per charge, on each section: the damaged extent, the crushed zone and the lattice
  bias (:mod:`mpipd.post.charges`);
* the energy ledger, every term of /energy (:mod:`mpipd.post.ledger`);
* the probes' histories (radial stress, radial velocity, pressure against time);
* with ``fragments``: the fragments of the last frame (``fragments/`` beside the
  report, :mod:`mpipd.post.fragment_report`).

Nothing here assumes a cylinder, one borehole or a tube.
"""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from . import alerts, ledger
from . import charges as ch
from . import sections as secs
from .analysis import pattern_frames
from .volume import _failure_modes


def analyse(run, model, pattern_us=None) -> tuple[dict, dict | None]:
    times = run.time
    last = run.frames - 1
    frames = pattern_frames(times, wanted_us=pattern_us)
    if last not in frames:
        frames.append(last)
    named = ch.rock_levels(run, model)
    reqs = [("damage", k) for k in frames] + [("failure_mode", last)]
    gathered = secs.gather_sections(run, model, named, reqs)
    usable = [c for c in model.charges if c["center"] and c["radius"]]
    per = None
    if run.root:
        per = {}
        for name, sec in (gathered or {}).items():
            try:
                per[name] = ch.measure(sec, usable, last)
            except KeyError as e:
                per = {"not_available": str(e).strip("'\"")}
                break
    per = run.comm.bcast(per, root=0)
    if not usable:
        per = {"not_available": "the scene has no charge of known position and radius"}
    lattice = ({s: {c: v["lattice_bias"] for c, v in d.items()} for s, d in per.items()}
               if "not_available" not in per else {})
    warnings = alerts.collect(run, model, lattice_measures=lattice)
    pid = run.geometry("part")
    fm = _failure_modes(run, model.is_rock(pid))
    from . import probe_metrics as pm
    probes = pm.load_probes(run, model)
    led = ledger.read(run)
    metrics = {"kind": "scene", "scene": model.scene_name,
               "parts": [{"name": n, "material": model.part_material.get(k)}
                         for k, n in enumerate(model.part_names)],
               "rock_part": model.part_names[model.rock],
               "charges": [{k: v for k, v in c.items() if k != "part"} for c in model.charges],
               "frames": run.frames, "t_end_us": float(times[-1]) * 1e6,
               "pattern_frames": frames,
               "pattern_times_us": [float(times[k]) * 1e6 for k in frames],
               "sections_mm": {n: z[model.rock] * 1e3 for n, z in named.items()},
               "per_charge": per, "failure_modes": fm, "energy_ledger": led,
               "probes": {n: {"part": p["part"], "material": p["material"],
                              "position_mm": [v * 1e3 for v in p["x"]],
                              "peak_sigma_rr_MPa": float(np.max(-p["sigma_rr"])) / 1e6
                              if len(p["sigma_rr"]) else None,
                              "peak_p_MPa": float(np.max(p["p"])) / 1e6 if len(p["p"]) else None,
                              "error": p["error"]}
                          for n, p in probes.items()},
               "warnings": warnings, "notes": model.notes}
    errs = [{"measure": f"probe {n}", "message": p["error"]} for n, p in sorted(probes.items())
            if p.get("error")]
    metrics["errors"] = errs + led.get("errors", [])
    data = {"sections": gathered, "probes": probes} if run.root else None
    return metrics, data


def figures(metrics, data, model, times, label, out: Path) -> tuple[dict, dict]:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    made, skipped = {}, {}
    sec = data["sections"] or {}
    frames = metrics["pattern_frames"]
    if sec and any(("damage", frames[-1]) in s for s in sec.values()):
        names = list(sec)
        fig, axes = plt.subplots(len(names), len(frames), squeeze=False,
                                 figsize=(3.2 * len(frames), 3.0 * len(names)), dpi=110)
        for i, n in enumerate(names):
            s = sec[n]
            for j, k in enumerate(frames):
                ax = axes[i][j]
                ax.scatter(s["x"] * 1e3, s["y"] * 1e3, c=s[("damage", k)], s=max(
                    1.0, 6e3 / max(len(s["x"]), 1)), marker="s", cmap="inferno", vmin=0, vmax=1)
                for c in model.charges:
                    if c["center"] and c["radius"]:
                        ax.add_patch(plt.Circle((c["center"][0] * 1e3, c["center"][1] * 1e3),
                                                c["radius"] * 1e3, fill=False, color="c", lw=0.8))
                ax.set_aspect("equal")
                ax.set_title(f"{n}, z {metrics['sections_mm'][n]:.3g} mm\n"
                             f"t = {times[k] * 1e6:.3g} us", fontsize=8)
                ax.tick_params(labelsize=7)
        fig.suptitle(f"damage of the rock ({model.part_names[model.rock]}): {label}", fontsize=9)
        fig.tight_layout()
        made["damage_sections"] = _save(fig, out / "damage_sections.png", plt)
    else:
        skipped["damage_sections"] = "the run has no damage field"
    last = metrics["frames"] - 1
    mid = ch.NAMES[1] if ch.NAMES[1] in sec else next(iter(sec), None)
    if mid is not None and ("failure_mode", last) in sec[mid]:
        from mpipd.kernels.layout import MODE_LABELS
        s = sec[mid]
        fig, ax = plt.subplots(figsize=(5.5, 4.8), dpi=110)
        mode = s[("failure_mode", last)].astype(int)
        sc = ax.scatter(s["x"] * 1e3, s["y"] * 1e3, c=mode, cmap="tab10", vmin=-0.5,
                        vmax=len(MODE_LABELS) - 0.5, s=max(1.0, 6e3 / max(len(mode), 1)),
                        marker="s")
        cb = fig.colorbar(sc, ax=ax, ticks=range(len(MODE_LABELS)))
        cb.ax.set_yticklabels(MODE_LABELS, fontsize=7)
        ax.set_aspect("equal")
        ax.set_xlabel("x (mm)")
        ax.set_ylabel("y (mm)")
        ax.set_title(f"failure mode, {mid}, t = {times[last] * 1e6:.3g} us", fontsize=9)
        fig.tight_layout()
        made["failure_modes"] = _save(fig, out / "failure_modes.png", plt)
    else:
        skipped["failure_modes"] = "the run has no failure_mode field"
    led = metrics["energy_ledger"]
    if "series_J" in led and led["series_J"]:
        fig, ax = plt.subplots(figsize=(7, 4.5), dpi=110)
        t = np.asarray(times[:len(next(iter(led["series_J"].values())))]) * 1e6
        for k, v in led["series_J"].items():
            if np.any(np.asarray(v) != 0):
                ax.plot(t, v, label=k)
        ax.set_xlabel("t (us)")
        ax.set_ylabel("J")
        ax.legend(fontsize=6, ncol=2)
        ax.set_title("energy ledger (/energy)", fontsize=9)
        fig.tight_layout()
        made["energy_ledger"] = _save(fig, out / "energy_ledger.png", plt)
    else:
        skipped["energy_ledger"] = led.get("not_available", "no ledger terms")
    probes = data["probes"]
    if probes:
        fig, axes = plt.subplots(3, 1, sharex=True, figsize=(7, 7), dpi=110)
        for n, p in probes.items():
            t = p["t"] * 1e6
            axes[0].plot(t, -p["sigma_rr"] / 1e6, label=n)
            axes[1].plot(t, p["v_r"], label=n)
            axes[2].plot(t, p["p"] / 1e6, label=n)
        for ax, lab in zip(axes, ("-sigma_rr (MPa)", "v_r (m/s)", "p (MPa)")):
            ax.set_ylabel(lab)
        axes[0].legend(fontsize=7)
        axes[2].set_xlabel("t (us)")
        fig.suptitle("probes (every step; radial about each probe's centre)", fontsize=9)
        fig.tight_layout()
        made["probes"] = _save(fig, out / "probes.png", plt)
    else:
        skipped["probes"] = "the scene has no probes"
    return made, skipped


def _save(fig, path, plt) -> str:
    fig.savefig(path)
    plt.close(fig)
    return path.name


def render(doc) -> str:
    run, m = doc["run"], doc
    L = [f"# Report: {run['label']}", "",
         f"Run file `{run['run_file']}`: {run['n_points']} points, {m['frames']} frames to "
         f"t = {m['t_end_us']:.3g} µs (dt {run['dt_s']} s, {run['steps']} steps, written by "
         f"{run['run_ranks']} rank(s)); mpipd {run['mpipd_version']}.",
         "Parts: " + ", ".join(f"`{p['name']}` ({p['material'] or '?'})" for p in m["parts"])
         + f".  The rock: `{m['rock_part']}`.  " + m["paper"]["reason"][:1].upper()
         + m["paper"]["reason"][1:] + ".", ""]
    notes = [n for n in m["notes"] if not n.startswith("the rock part is a")]
    L += [f"Note: {n}" for n in notes] + ([""] if notes else [])
    L += ["## Warnings", ""]
    L += (["\n".join(f"- **{w['message']}.**  *Fix*: {w['fix']}." for w in
                     m["warnings"])] if m["warnings"] else ["None."])
    L += ["", "## Errors", ""]
    L += ([f"- **{e['measure']}**: {e['message']}" for e in m["errors"]]
          or ["None: no impossible value was found."])
    L += ["", "## Damage on sections through the rock", "",
          "Sections (z of the rock's lattice level; rock points only): "
          + ", ".join(f"{k} {v:.3g} mm" for k, v in m["sections_mm"].items())
          + f".  Times: {', '.join(f'{t:.3g}' for t in m['pattern_times_us'])} µs.", ""]
    L += _fig(doc, "damage_sections")
    L += ["## Failure modes", ""]
    fm = m["failure_modes"]
    L += ["Rock points by failure mode at the last frame: " + (
        fm["not_available"] if "not_available" in fm else
        ", ".join(f"{k} {v}" for k, v in fm.items() if k != "note")) + ".", ""]
    L += _fig(doc, "failure_modes")
    L += ["## Per charge: damaged extent, crushed zone, lattice bias", ""]
    per = m["per_charge"]
    if "not_available" in per:
        L += [f"Not available: {per['not_available']}.", ""]
    else:
        L += ["Each rock point of a section belongs to the charge whose axis is nearest.  "
              "Damaged extent: the farthest failed point from the charge's axis.  Crushed "
              "zone: the unbroken run of rings (width dx) from the hole's wall with at least "
              "90 % of their points failed.  Lattice bias: a_4 of the failed points in the "
              "middle third between the wall and the room around the charge (0: no "
              "preferred direction; noise: its value for failure regardless of angle).", "",
              "| section | charge | failed points | damaged extent (mm from axis / hole radii "
              "beyond wall) | crushed zone (mm beyond wall / hole radii) | room (mm) | a_4 "
              "(noise) |", "|---|---|---|---|---|---|---|"]
        for s, d in per.items():
            for c, v in d.items():
                de = ("—" if v["damaged_extent_mm"] is None else
                      f"{v['damaged_extent_mm']:.3g} / {v['damaged_extent_hole_radii']:.2f}")
                cz = v["crushed_zone"]
                czs = ("n/a" if "not_available" in cz else
                       f"{cz['extent_mm']:.3g} / {cz['extent_hole_radii']:.2f}")
                lb = v["lattice_bias"]
                lbs = ("n/a" if "a4" not in lb else f"{lb['a4']:.2f} ({lb['noise']:.2f})")
                L.append(f"| {s} | {c} | {v['failed_points']} of {v['points']} | {de} | {czs} | "
                         f"{v['r_free_mm']:.3g} | {lbs} |")
        L.append("")
    L += _ledger(m["energy_ledger"]) + _fig(doc, "energy_ledger")
    L += ["## Probes", ""]
    if m["probes"]:
        L += ["| probe | part | position (mm) | peak −σ_rr (MPa) | peak p (MPa) | check |",
              "|---|---|---|---|---|---|"]
        for n, p in m["probes"].items():
            L.append(f"| {n} | {p['part']} | {', '.join(f'{v:.3g}' for v in p['position_mm'])} | "
                     f"{_num(p['peak_sigma_rr_MPa'])} | {_num(p['peak_p_MPa'])} | "
                     f"{'**error**: ' + p['error'] if p.get('error') else 'ok'} |")
        L.append("")
    else:
        L += ["The scene has no probes.", ""]
    L += _fig(doc, "probes")
    if doc.get("fragments"):
        L += ["## Fragments", "", doc["fragments"], ""]
    if doc["figures_not_made"]:
        L += ["## Not made", ""] + [f"- figure {k}: {v}" for k, v in
                                    doc["figures_not_made"].items()] + [""]
    return "\n".join(L) + "\n"


def _num(v):
    return "—" if v is None else f"{v:.4g}"


def _fig(doc, name):
    if name in doc["figures"]:
        return [f"![{name}]({doc['figures'][name]})", ""]
    return [f"*Figure {name} not made: {doc['figures_not_made'].get(name, 'no data')}.*", ""]


def _ledger(led) -> list[str]:
    L = ["## Energy ledger (`/energy`)", ""]
    if "not_available" in led:
        return L + [f"Not available: {led['not_available']}.", ""]
    L += ["Every term of the file's /energy, final value; the books close as initial + "
          "external + boundary = held + dissipated.", "", "| term | final value (J) |",
          "|---|---|"]
    for k, v in led["final_J"].items():
        L.append(f"| {k} | {'**error**: ' + v['error'] if isinstance(v, dict) else _num(v)} |")
    b = led.get("max_abs_balance")
    L += ["", "Largest |balance| (relative closure error): " + (
        "not in the file" if b is None else f"{b:.3g} at frame {led['max_abs_balance_frame']}")
        + ".", ""]
    return L


def write(doc, out: Path) -> None:
    from .report import _json
    (out / "report.json").write_text(json.dumps(doc, indent=1, default=_json) + "\n")
    (out / "report.md").write_text(render(doc))
