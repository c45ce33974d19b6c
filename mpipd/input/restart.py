"""What a restart may change of its run's scene.

A restart continues the same physics: only the run length, the checkpoint and
progress cadence, the ledger's stop bound and the description may change
(:data:`RESTART_MAY_CHANGE`); any other key that differs from the checkpoint's
scene is bad input naming it (:func:`check_same_physics`).  ``output.every`` and
``time.dt`` are refused by the run folder's checks (mpipd.output.rundir.check_restart),
with their own lines.
"""
from __future__ import annotations

import dataclasses
import json
import re

from .schema import SceneError

#: scene keys a restart may change: the run length, the checkpoint and progress
#: cadence, the ledger's stop bound and the description (output.every may not
#: change either, check_restart says why; everything else is the run's physics or
#: the run file's layout)
RESTART_MAY_CHANGE = ("time.steps", "time.t_end", "output.checkpoint_every",
                      "solver.progress_every", "solver.max_imbalance", "scene.description")


def _diff(a, b, path: str, out: list) -> None:
    """Append to ``out`` the key paths where scene values ``a`` and ``b`` differ
    (dataclasses field by field, tables key by key, arrays of tables entry by
    entry; an array of plain values is one value)."""
    import numpy as np
    if dataclasses.is_dataclass(a) and not isinstance(a, type):
        if type(a) is not type(b):
            out.append(path)
            return
        for f in dataclasses.fields(a):
            if f.init:
                _diff(getattr(a, f.name), getattr(b, f.name),
                      f"{path}.{f.name}" if path else f.name, out)
        return
    if isinstance(a, dict):
        if not isinstance(b, dict):
            out.append(path)
            return
        for k in list(a) + [k for k in b if k not in a]:
            if k not in a or k not in b:
                out.append(f"{path}.{k}")
            else:
                _diff(a[k], b[k], f"{path}.{k}", out)
        if list(a) != list(b) and set(a) == set(b):    # the order numbers the materials
            out.append(path)
        return
    if isinstance(a, (tuple, list)) and any(dataclasses.is_dataclass(v) for v in a):
        if not isinstance(b, (tuple, list)) or len(a) != len(b):
            out.append(path)
            return
        for i, (x, y) in enumerate(zip(a, b)):
            _diff(x, y, f"{path}.{i}", out)
        return
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        if not (np.shape(a) == np.shape(b) and np.array_equal(a, b)):
            out.append(path)
        return
    if type(a) is not type(b) or a != b:
        out.append(path)


def _shown_value(scene, path: str) -> str:
    """The value at key path ``path`` of a scene, short, for a message."""
    node = scene
    for part in re.findall(r"[^.\[\]]+", path):
        try:
            node = (node[int(part)] if part.isdigit() and isinstance(node, (tuple, list))
                    else node[part] if isinstance(node, dict) else getattr(node, part))
        except (KeyError, IndexError, AttributeError, TypeError):
            return "(absent)"
    if dataclasses.is_dataclass(node):
        return "(a table)"
    text = json.dumps(list(node) if isinstance(node, tuple) else node, default=str)
    return text if len(text) <= 60 else text[:57] + "..."


def scene_changes(old, new) -> list[str]:
    """The key paths where scene ``new`` (a restart's) differs from ``old`` (its
    checkpoint's) other than RESTART_MAY_CHANGE, in scene order."""
    diffs: list[str] = []
    _diff(old, new, "", diffs)
    return [d for d in diffs if d not in RESTART_MAY_CHANGE]


def check_same_physics(old, new) -> None:
    """A restart continues its run: refuse (one line naming the first key) a scene
    that differs from the checkpoint's beyond RESTART_MAY_CHANGE.  output.every and
    time.dt keep check_restart's own lines."""
    changed = [d for d in scene_changes(old, new) if d not in ("output.every", "time.dt")]
    if changed:
        key = changed[0]
        more = f" (and {len(changed) - 1} more key(s))" if len(changed) > 1 else ""
        raise SceneError(key, f"a restart continues its run and cannot change it "
                              f"({_shown_value(old, key)} -> {_shown_value(new, key)}){more}; "
                              "a restart may change only " + ", ".join(RESTART_MAY_CHANGE)
                         + " (rerun the scene with --out elsewhere for other values)")
