"""``python -m mpipd.post compare RUN.h5 RUN.h5 ... [--out DIR]``: several runs side
by side — the discretisation study (paper §3.4, Figs. 19–21) and the Table 3
sensitivity cases (§3.5, Fig. 22).

Each run is analysed exactly as by ``report`` (:func:`mpipd.post.analysis.analyse`,
all ranks, one run after another); rank 0 then writes

* ``compare.md`` / ``compare.json`` — the target measures of every run in one
  table (value and verdict), with each run's points, dx, overrides;
* ``compare_fracture.png`` — damage on one section of each run at its last frame
  (default the detonation end face, the view of Figs. 19 and 22);
* ``compare_energy.png`` — energy in the rock against time (Fig. 20);
* ``compare_peak_stress.png`` — peak radial stress against distance (Fig. 21).
"""
from __future__ import annotations

import json
from pathlib import Path

from . import figures_curves as fc
from . import figures_maps as fmap
from .analysis import analyse
from .model import load_model
from .reader import Run, shown_path
from .report import _json, run_label
from .sections import NAMED
from .targets import TARGETS

VIEWS = {"detonation-face": NAMED[0], "mid": NAMED[2], "far-face": NAMED[4]}


def _cell(row) -> str:
    v = row["value"]
    if row["verdict"].startswith("error"):
        return "error"
    if v is None:
        return "n/a"
    shown = ("yes" if v else "no") if row["unit"] == "yes/no" else f"{v:.4g}"
    if row["verdict"] == "information":
        return shown
    return f"{shown} ({'in' if row['verdict'] == 'within' else 'out'})"


def render(runs) -> str:
    head = "| quantity | paper / experiment | " + " | ".join(r["label"] for r in runs) + " |"
    L = ["# Comparison of runs", "", head, "|---|---|" + "---|" * len(runs)]
    info = [("points", lambda r: str(r["n_points"])),
            ("rock dx (mm)", lambda r: f"{r['model']['dx_m'] * 1e3:.3g}"),
            ("t_end (µs)", lambda r: f"{r['t_end_us']:.3g}"),
            ("overrides", lambda r: "<br>".join(r["model"]["overrides"]) or "—")]
    for name, fn in info:
        L.append(f"| {name} | | " + " | ".join(fn(r) for r in runs) + " |")
    for k, t in enumerate(TARGETS):
        ref = " / ".join(f"{who}: {v}" for who, v in (("paper", t.paper), ("exp.", t.experiment))
                         if v not in ("—", ""))
        L.append(f"| {t.label} ({t.unit}) | {ref} | "
                 + " | ".join(_cell(r["targets"][k]) for r in runs) + " |")
    L.append("| failed rock points by mode (plastic / tensile / tension) | | " + " | ".join(
        "n/a" if "not_available" in r["failure_modes"] else
        " / ".join(str(v) for k, v in list(r["failure_modes"].items())[1:4]) for r in runs)
        + " |")
    L.append("| peak energy in the rock (J) | | " + " | ".join(
        "error" if "error" in r["energy"] else "n/a" if "not_available" in r["energy"] else
        f"{max(r['energy']['total_J'] or r['energy']['kinetic_J']):.4g}" for r in runs) + " |")
    L.append("| errors (impossible values) | | " + " | ".join(
        str(len(r["errors"])) for r in runs) + " |")
    L += ["", "'in' / 'out': within / outside the range of `mpipd/post/targets.py` (see a "
          "run's report for the ranges); 'error': an impossible value (see the run's report).",
          "",
          "![fracture](compare_fracture.png)", "", "![energy](compare_energy.png)", "",
          "![peak radial stress](compare_peak_stress.png)", ""]
    return "\n".join(L) + "\n"


def make_compare(paths, out, comm, labels=None, view="detonation-face") -> list[str]:
    section = VIEWS[view]
    runs, pictures = [], []
    for k, path in enumerate(paths):
        run = Run(path, comm)
        try:
            model = load_model(run)
            label = labels[k] if labels else run_label(path, model)
            model.label = label
            metrics, data = analyse(run, model)
            n_points = run.n_points
        finally:
            run.close()
        if comm.Get_rank() == 0:
            last = metrics["frames"] - 1
            z = data["sections"]["levels"][section]
            pictures.append((label, model, data["sections"]["sections"].get(section),
                             ("damage", last), metrics["t_end_us"], z * 1e3))
            runs.append({"label": label, "run_file": shown_path(path),
                         "n_points": n_points, **metrics})
    if comm.Get_rank() != 0:
        return []
    if len({r["label"] for r in runs}) < len(runs):
        for k, r in enumerate(runs):
            r["label"] = f"{k + 1}: {r['label']}"
            pictures[k] = (r["label"],) + pictures[k][1:]
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    figs = [fmap.compare_patterns(pictures, section, out / "compare_fracture.png")]
    figs += fc.compare_curves([(r["label"], r) for r in runs], out / "compare_energy.png",
                              out / "compare_peak_stress.png")
    (out / "compare.json").write_text(json.dumps({"runs": runs, "figures": figs}, indent=1,
                                                 default=_json) + "\n")
    (out / "compare.md").write_text(render(runs))
    return [f"wrote {out / 'compare.md'}, {out / 'compare.json'} and {len(figs)} figures "
            f"for {len(runs)} runs"]
