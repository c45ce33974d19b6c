"""``python -m mpipd.post report RUN.h5 [--out DIR] [--paper | --no-paper]
[--fragments]``: the report of one run (``report.md``, the same numbers in
``report.json``, and figures).

Which report: the paper's validation report (its figures, targets, experiment bars,
zones and Fig. 11 sections) when the scene is the paper's specimen
(:func:`mpipd.post.model.paper_geometry`: a cylinder of rock with one charge on its
axis in a tube) or with ``--paper``; else the report of any scene
(:mod:`mpipd.post.scene_report`).  Both carry the warnings of :mod:`mpipd.post.alerts`.

All ranks read and reduce (:mod:`mpipd.post.analysis`); rank 0 draws the figures
and writes the files.  The JSON holds only numbers derived from the run file, so
it is identical whatever the number of reading ranks.
"""
from __future__ import annotations

import json
from pathlib import Path

from . import figures_curves as fc
from . import figures_maps as fmap
from .analysis import analyse
from .model import load_model
from .reader import Run, shown_path


def run_label(path, model) -> str:
    p = Path(path).resolve()
    folder = p.parent.name if p.name == "run.h5" else p.stem
    return f"{model.scene_name} ({folder})"


def _figures(metrics, data, model, times, label, out: Path) -> tuple[dict, dict]:
    """Draw every figure the data allow: name -> file, and name -> why not."""
    made, skipped = {}, {}
    last = metrics["frames"] - 1
    frames = metrics["pattern_frames"]
    fr = metrics["fracture"]
    sec = data["sections"]

    def put(name, why, fn, *args):
        if why:
            skipped[name] = why
        else:
            made[name] = fn(*args)
    has_damage = any(("damage", last) in s for s in sec["sections"].values())
    has_mode = any(("failure_mode", last) in s for s in sec["sections"].values())
    no_dmg = None if has_damage else "the run has no damage field"
    put("fig09_fracture_faces", no_dmg, fmap.fracture_pattern, sec, model, times, frames, label,
        out / "fig09_fracture_faces.png")
    fig11 = [n for n in fmap.FIG11_ROWS if n in sec["levels"]]
    put("fig11_fracture_sections", no_dmg or (None if fig11 else "no Fig. 11 section in the rock "
                                              "(the rock is thinner than its sections)"),
        fmap.fracture_sections, sec, model, times, frames, label,
        out / "fig11_fracture_sections.png")
    put("fig13_failure_modes", None if has_mode else "the run has no failure_mode field",
        fmap.failure_modes, sec, model, times, last, label, out / "fig13_failure_modes.png")
    put("fig12_crack_density", fr.get("not_available"), fc.crack_density, fr, label,
        out / "fig12_crack_density.png")
    rs = metrics["radial_stress"]
    put("fig16a_radial_stress", rs.get("not_available"), fc.radial_histories, data["probes"], rs,
        label, out / "fig16a_radial_stress.png")
    ws = metrics["wave_speed"]
    put("fig16b_wave_speed", ws.get("not_available") if not ws.get("arrivals") else None,
        fc.arrivals, ws, label, out / "fig16b_wave_speed.png")
    put("fig17_peak_radial_stress", rs.get("not_available"), fc.peak_stress, rs, label,
        out / "fig17_peak_radial_stress.png")
    pv, prof = metrics["ppv"], metrics["ppv_profile"]
    why = pv.get("not_available") if "not_available" in prof else None
    put("fig18_ppv", why, fc.ppv, pv, prof, label, out / "fig18_ppv.png")
    ps = metrics["pressure_stress"]
    put("fig15_pressure_stress", ps.get("not_available"), fc.pressure_stress, data["probes"], ps,
        model.jh2, label, out / "fig15_pressure_stress.png")
    fs = metrics["frame_series"]
    has_gas = metrics["gas_profiles"] or any(fs[k] for k in fs if k != "note")
    put("fig07_explosive_pressure", None if has_gas else "the run has no pressure or stress field",
        fc.explosive_pressure, metrics, label, out / "fig07_explosive_pressure.png")
    plane = data["plane"]
    put("fig07_pressure_plane", None if plane is not None else "the run has no pressure field",
        fmap.plane_pressure, plane, model, times, data["plane_frames"], label,
        out / "fig07_pressure_plane.png")
    en = metrics["energy"]
    put("fig20_rock_energy", en.get("not_available") or
        (f"error: {en['error']}" if "error" in en else None), fc.energy, metrics, label,
        out / "fig20_rock_energy.png")
    return made, skipped


def make_report(path, out, comm, pattern_us=None, paper=None, fragments=False) -> list[str]:
    """``paper``: None decides from the scene, True/False forces the paper's report or
    the report of any scene."""
    from . import alerts
    from .model import paper_geometry
    run = Run(path, comm)
    try:
        model = load_model(run)
        label = run_label(path, model)
        model.label = label
        is_paper, reason = paper_geometry(model)
        use_paper = is_paper if paper is None else bool(paper)
        if use_paper:
            metrics, data = analyse(run, model, pattern_us)
            lat = {n: {"around the borehole": v} for n, v in metrics["lattice_bias"].items()
                   if n != "ring"} if "not_available" not in metrics["lattice_bias"] else {}
            warnings = alerts.collect(run, model, lattice_measures=lat,
                                      tube_result=metrics.get("tube_containment"))
        else:
            from . import scene_report
            metrics, data = scene_report.analyse(run, model, pattern_us)
            warnings = metrics.pop("warnings")
        times = run.time
        info = {"run_file": shown_path(path), "label": label,
                "n_points": run.n_points, "run_ranks": _int(run.attr("ranks")),
                "dt_s": _float(run.attr("dt")), "steps": _int(run.attr("steps")),
                "git_commit": str(run.attr("git_commit", "unknown")),
                "mpipd_version": str(run.attr("mpipd_version", "unknown")),
                "fields": run.field_names, "bonds_broken": _int(run.attr("bonds_broken"))}
        info.update(run_id=run.attr("run_id"), n_bonds=_int(run.attr("n_bonds")),
                    save_every=_int(run.attr("every")),
                    segments=json.loads(run.attr("segments", "[]")))
    finally:
        run.close()
    frag = _fragments(path, out, comm) if fragments else None
    if comm.Get_rank() != 0:
        return []
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    if not use_paper:
        from . import scene_report
        made, skipped = scene_report.figures(metrics, data, model, times, label, out)
        doc = {"run": info, "paper": {"applied": False, "scene_is_paper": is_paper,
                                      "reason": ("the paper's validation is not applied: "
                                                 + reason) if not is_paper else
                                      "the paper's validation is not applied (--no-paper)"},
               "warnings": warnings, "figures": made, "figures_not_made": skipped,
               **metrics, "fragments": frag}
        scene_report.write(doc, out)
        return _done(out, made, skipped, warnings)
    made, skipped = _figures(metrics, data, model, times, label, out)
    doc = {"run": info, "errors": metrics["errors"], "figures": made,
           "figures_not_made": skipped, **metrics}
    from .report_md import render
    doc["warnings"] = warnings
    doc["paper"] = {"applied": True, "scene_is_paper": is_paper,
                    "reason": reason if is_paper else f"--paper (the scene is not: {reason})"}
    if frag:
        doc["fragments"] = frag
    (out / "report.json").write_text(json.dumps(doc, indent=1, default=_json) + "\n")
    md = render(doc)
    from .alerts import lines as warn_lines
    block = warn_lines(warnings)
    if frag:
        md += "\n## Fragments\n\n" + frag + "\n"
    md = md.replace("\n## Errors\n", "\n## Warnings\n\n" + ("\n".join(
        f"- **{w['message']}.**  *Fix*: {w['fix']}." for w in warnings)
        if block else "None.") + "\n\n## Errors\n", 1)
    (out / "report.md").write_text(md)
    return _done(out, made, skipped, warnings)


def _done(out, made, skipped, warnings) -> list[str]:
    from .alerts import lines as warn_lines
    return ([f"wrote {out / 'report.md'}, {out / 'report.json'} and {len(made)} figures"
             + (f" ({len(skipped)} not made: {', '.join(skipped)})" if skipped else "")]
            + warn_lines(warnings))


def _fragments(path, out, comm) -> str:
    """The fragments of the last frame into OUT/fragments (rank 0 sees the lines)."""
    from .fragment_report import make_fragments
    lines = make_fragments(path, str(Path(out) / "fragments"), comm)
    return ("`fragments/`: " + " ".join(lines)) if lines else "`fragments/`"


def _int(v):
    return None if v is None else int(v)


def _float(v):
    return None if v is None else float(v)


def _json(o):
    import numpy as np
    if isinstance(o, np.generic):
        return o.item()
    if isinstance(o, np.ndarray):
        return o.tolist()
    return str(o)
