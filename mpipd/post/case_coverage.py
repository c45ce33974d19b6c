"""Which named cases of a built-in scene the validation record has run, and whether
each of those runs reached the case's t_end (issue 15: "every named case ... runs to
its t_end").

A record row ran case ``c`` of built-in scene ``s`` when its report.json names the
scene ``s-c`` (``mpipd run s:c`` names its run so; the base scene is ``s``).  A run
of two cases together, ``s-c1-c2``, is listed under each, with the other's settings
as extras.  A row's *extras* are its ``--set`` overrides less the case's own, the
``scene.name`` the case sets and the ``output.*`` settings (which do not change the
physics); a row that *lacks* one of the case's overrides did not run the case as it
is named now.  A row ran the scene as its commit had it: the scene file and the
case's overrides at that commit (``git show``) are compared, as parsed TOML, with
today's, and a row whose scene changed since is listed with that.  The case's t_end
is the scene's, loaded with the case and the row's extras
(:func:`mpipd.input.scene.load`); a row reached it when its last frame's time is
within half a step of it.  A case counts as run when a row ran it at its own
settings, on today's scene, to its t_end.
"""
from __future__ import annotations

import subprocess
from functools import lru_cache
from pathlib import Path

import tomllib

from mpipd.input import scene as sc

ROOT = Path(__file__).resolve().parents[2]       # the repository
#: where a built-in scene's file has lived (the latter before the input/ folder)
SCENE_DIRS = ("mpipd/input/scenes", "mpipd/scenes")


def base_of(scene_name: str, builtins) -> tuple[str, list[str]] | None:
    """``"blast_paper-dx1.2"`` -> ("blast_paper", ["dx1.2"]); ``"s-c1-c2"`` -> (s,
    [c1, c2]) when both are cases of s (else the whole tail as one name); the base
    scene itself -> (name, [""]); a scene no built-in's name starts -> None."""
    for b in sorted(builtins, key=len, reverse=True):
        if scene_name == b:
            return b, [""]
        if scene_name.startswith(b + "-") and len(scene_name) > len(b) + 1:
            tail = scene_name[len(b) + 1:]
            parts = tail.split("-")
            known = sc.cases(b)
            return b, parts if len(parts) > 1 and all(p in known for p in parts) else [tail]
    return None


def _norm(o: str) -> str:
    return "".join(o.split())


def _key(o: str) -> str:
    return o.split("=", 1)[0].strip()


def extras(overrides, case_set) -> tuple[list[str], list[str]]:
    """(the row's overrides beyond its case's own, not ``scene.name`` nor ``output.*``;
    the case's overrides the row lacks)."""
    own = {_norm(o) for o in case_set}
    have = {_norm(o) for o in overrides}
    more = [o for o in overrides if _norm(o) not in own
            and not (_key(o) == "scene.name" or _key(o).startswith("output."))]
    return more, [o for o in case_set if _norm(o) not in have]


def t_end_s(base: str, case: str, more) -> float | None:
    """The t_end (s) of ``base:case`` with the overrides ``more``; None if it does not
    load (a case renamed or removed since the run)."""
    try:
        s, _ = sc.load(f"{base}:{case}" if case else base, list(more))
    except sc.SceneError:
        return None
    return s.time.n_steps * s.time.dt


@lru_cache(maxsize=None)
def _file_at(commit: str, rel: str) -> dict | None:
    """The TOML file ``<scene dir>/rel`` at ``commit``, parsed; None if git or the
    file is not there."""
    for d in SCENE_DIRS:
        try:
            p = subprocess.run(["git", "-C", str(ROOT), "show", f"{commit}:{d}/{rel}"],
                               capture_output=True, text=True, timeout=20)
        except (OSError, subprocess.SubprocessError):
            return None
        if p.returncode == 0:
            try:
                return tomllib.loads(p.stdout)
            except tomllib.TOMLDecodeError:
                return None
    return None


def scene_changed(commit: str | None, base: str, case: str) -> str | None:
    """Why the row's scene differs from today's (its scene file, or the case's
    overrides, at its commit), "" if it does not, None if that cannot be checked."""
    if not commit:
        return None
    commit = commit.removesuffix("-dirty")
    then = _file_at(commit, f"{base}.toml")
    if then is None:
        return None
    now = tomllib.loads(sc.builtin_scenes()[base].read_text())
    if then != now:
        return f"{base}.toml has changed since"
    if case:
        cases_then = _file_at(commit, f"cases/{base}.toml") or {}
        was = cases_then.get(case, {}).get("set")
        if was is None or sorted(map(_norm, was)) != sorted(map(_norm, sc.cases(base)[case].set)):
            return "the case's overrides have changed since"
    return ""


def row_cell(r, base, case, case_set) -> tuple[str, bool]:
    """The row's cell text, and whether it ran the case at its own settings, on
    today's scene, to its t_end."""
    doc = r["doc"]
    more, lacks = extras(doc.get("model", {}).get("overrides") or [], case_set)
    end = t_end_s(base, case, more)
    reached = doc.get("t_end_us")
    done = False
    if end is None or reached is None:
        state = "t_end not known"
    else:
        dt = doc["run"].get("dt_s")
        tol = 0.5 * dt * 1e6 if dt else 1e-6 * end * 1e6
        done = reached >= end * 1e6 - tol
        state = f"{reached:.4g} of {end * 1e6:.4g} µs" + ("" if done else ": **stopped early**")
    full = str(doc["run"].get("git_commit") or "")
    commit = full[:7] + ("-dirty" if full.endswith("-dirty") else "") if full else \
        "commit not in report.json"
    changed = scene_changed(full or None, base, case)
    notes = [f"also {', '.join(f'`{o}`' for o in more)}" if more else "",
             f"lacks {', '.join(f'`{o}`' for o in lacks)}" if lacks else "",
             "scene at its commit not checked" if changed is None else changed]
    tail = "".join(f"; {n}" for n in notes if n)
    return (f"{r['case']} ({state}, {commit}{tail})",
            done and not more and not lacks and changed == "")


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
         "the rows that ran it: the simulated time each reached against the case's t_end, "
         "the commit it ran at, its settings beyond the case's (*also*; `output.*` left out) "
         "or missing from them (*lacks*), and whether the scene file or the case has changed "
         "since that commit.  A case counts when a row ran it at its own settings, on "
         "today's scene, to its t_end.  Only this record's rows count (`make cases` runs "
         "every case of blast_demo: studies/cases/blast_demo.md).  Read from report.json, the "
         "scene files and git (mpipd/post/case_coverage.py).", ""]
    for base in sorted(by_scene):
        known = sc.cases(base)
        L += [f"### {base}", "", "| case | study | what it changes | rows |", "|---|---|---|---|"]
        missing = []
        for name, case in [("", None), *known.items()]:
            rows = [r for c, r in by_scene[base] if c == name]
            case_set = case.set if case is not None else ()
            made = [row_cell(r, base, name, case_set) for r in rows]
            if not any(own for _, own in made):
                missing.append(name or "(the scene)")
            what = case.description if case is not None else "the scene as it is"
            study = case.study if case is not None else "—"
            cells = "<br>".join(text for text, _ in made) or "not run in this record"
            L.append(f"| {name or '(the scene)'} | {study} | {what.replace('|', '/')} | {cells} |")
        unknown = sorted({c for c, _ in by_scene[base] if c and c not in known})
        L.append("")
        if unknown:
            L += [f"Rows of {base} cases that its cases file no longer names: "
                  + ", ".join(unknown) + ".", ""]
        L += [f"{base}: {len(known) + 1 - len(missing)} of {len(known) + 1} (the scene and "
              f"its {len(known)} cases) have a row at their own settings, on today's scene, "
              "that reached t_end; not: " + (", ".join(missing) if missing else "none") + ".",
              ""]
    return L
