"""Which named cases of a built-in scene the validation record has run, and whether
each of those runs reached the case's t_end (issue 15: "every named case ... runs to
its t_end").

A record row ran case ``c`` of built-in scene ``s`` when its report.json names the
scene ``s-c`` (``mpipd run s:c`` names its run so; the base scene is ``s``; a run of
two cases together, ``s-c1-c2``, counts under each).  The
row's own ``--set`` overrides, less the case's, the ``scene.name`` the case sets and
the ``output.*`` settings (which do not change the physics), are its *extra*
overrides: a row with extras ran the case at other settings (another resolution or
integration) and is listed with them.  The case's t_end is the scene's, loaded with
the case and those extras (:func:`mpipd.input.scene.load`); a row reached it when
its last frame's time is within half a step of it.
"""
from __future__ import annotations

from mpipd.input import scene as sc


def base_of(scene_name: str, builtins) -> tuple[str, list[str]] | None:
    """``"blast_paper-dx1.2"`` -> ("blast_paper", ["dx1.2"]); ``"s-c1-c2"`` -> (s,
    [c1, c2]) when both are cases of s (else the whole tail as one name); the base
    scene itself -> (name, [""]); a scene no built-in's name starts -> None."""
    for b in sorted(builtins, key=len, reverse=True):
        if scene_name == b:
            return b, [""]
        if scene_name.startswith(b + "-"):
            tail = scene_name[len(b) + 1:]
            parts = tail.split("-")
            known = sc.cases(b)
            return b, parts if len(parts) > 1 and all(p in known for p in parts) else [tail]
    return None


def extras(overrides, case_set) -> list[str]:
    """A row's overrides beyond its case's: not the case's own, not ``scene.name`` and
    not ``output.*``."""
    own = {o.replace(" ", "") for o in case_set}
    return [o for o in overrides
            if o.replace(" ", "") not in own and not o.startswith(("scene.name=", "output."))]


def t_end_s(base: str, case: str, more) -> float | None:
    """The t_end (s) of ``base:case`` with the overrides ``more``; None if it does not
    load (a case renamed or removed since the run)."""
    try:
        s, _ = sc.load(f"{base}:{case}" if case else base, list(more))
    except sc.SceneError:
        return None
    return s.time.n_steps * s.time.dt


def row_cell(r, base, case, case_set) -> tuple[str, bool]:
    """The row's cell text, and whether it ran the case at the case's own settings
    (no extras) to its t_end."""
    doc = r["doc"]
    more = extras(doc.get("model", {}).get("overrides") or [], case_set)
    end = t_end_s(base, case, more)
    reached = doc.get("t_end_us")
    done = False
    if end is None or reached is None:
        state = "t_end not known"
    else:
        half = 0.5 * (doc["run"].get("dt_s") or 0.0) * 1e6
        done = reached >= end * 1e6 - half
        state = f"{reached:.4g} of {end * 1e6:.4g} µs" + ("" if done else ": **stopped early**")
    extra = "; also " + ", ".join(f"`{o}`" for o in more) if more else ""
    commit = str(doc["run"].get("git_commit") or "commit not in report.json")
    commit = commit[:7] + ("-dirty" if commit.endswith("-dirty") else "")
    return f"{r['case']} ({state}, {commit}{extra})", done and not more


def coverage_table(runs) -> list[str]:
    """The section "Named cases": for each built-in scene a row names, its base and
    each named case, with the rows that ran it (module docstring)."""
    builtins = sc.builtin_scenes()
    by_scene: dict[str, list] = {}
    for r in runs:
        name = r["doc"].get("model", {}).get("scene")
        hit = base_of(name, builtins) if name else None
        if hit is not None:
            by_scene.setdefault(hit[0], []).extend((c, r) for c in hit[1])
    if not by_scene:
        return []
    L = ["## Named cases", "",
         "Each named case of the scenes this record's rows ran (`mpipd cases SCENE`), with "
         "the rows that ran it and the simulated time each reached against the case's "
         "t_end; *also* names a row's settings beyond the case's (another resolution or "
         "integration; `output.*` left out), and the commit it ran at.  Only this record's "
         "rows count (`make cases` runs every case of blast_demo: docs/cases/blast_demo.md).  "
         "Read from report.json and the scene files (postprocess/case_coverage.py).", ""]
    for base in sorted(by_scene):
        known = sc.cases(base)
        L += [f"### {base}", "", "| case | study | what it changes | rows |", "|---|---|---|---|"]
        missing = []
        for name, case in [("", None), *known.items()]:
            rows = [r for c, r in by_scene[base] if c == name]
            case_set = case.set if case is not None else ()
            made = [row_cell(r, base, name, case_set) for r in rows]
            cells = "<br>".join(text for text, _ in made)
            if not any(own for _, own in made):
                missing.append(name or "(the scene)")
            what = case.description if case is not None else "the scene as it is"
            study = case.study if case is not None else "—"
            L.append(f"| {name or '(the scene)'} | {study} | {what.replace('|', '/')} | "
                     f"{cells or 'not run in this record'} |")
        unknown = sorted({c for c, _ in by_scene[base] if c and c not in known})
        L.append("")
        if unknown:
            L += [f"Rows of {base} cases that its cases file no longer names: "
                  + ", ".join(unknown) + ".", ""]
        L += [f"{base}: {len(known) + 1 - len(missing)} of {len(known) + 1} (the scene and "
              f"its {len(known)} cases) have a row at their own settings that reached t_end; not: "
              + (", ".join(missing) if missing else "none") + ".", ""]
    return L
