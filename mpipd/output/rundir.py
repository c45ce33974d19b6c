"""The run directory: which files belong to a run, and who may write them.

A run directory ``OUT`` holds one run's files::

    OUT/run.h5              the run file (mpipd.output.writer), attribute ``run_id``
    OUT/run.xdmf            its ParaView index
    OUT/run.log             the log (appended to by restarts)
    OUT/checkpoint.h5       the last checkpoint (mpipd.output.checkpoint), attribute ``run_id``
    OUT/checkpoint_failed.h5  the state at a blow-up

A run draws a random **run id** when it creates ``run.h5`` and writes it into
every checkpoint it makes.  A restart continues the run file of its own run
only: it is refused (exit 2, one line) when ``OUT/run.h5`` is missing, carries
another run id, or holds another scene text, point count or frame layout.
``--overwrite`` replaces a run: it deletes the old run's checkpoints and log,
so nothing can later be resumed into the new run file.

Nothing here calls MPI: the CLI calls these functions on rank 0 and broadcasts
the outcome.
"""
from __future__ import annotations

import errno
import os
import re
import uuid
from dataclasses import dataclass
from pathlib import Path

from ..parallel.team import Fatal

RUN_FILE = "run.h5"
CHECKPOINT = "checkpoint.h5"
#: files of the old run that ``--overwrite`` removes (run.h5 and run.xdmf are rewritten)
OLD_RUN_FILES = ("checkpoint.h5", "checkpoint.h5.tmp", "checkpoint_failed.h5",
                 "checkpoint_failed.h5.tmp", "run.log")


class RunDirError(ValueError):
    """A run directory that this run must not (or cannot) write."""


def new_run_id() -> str:
    return uuid.uuid4().hex


@dataclass(frozen=True)
class RunFile:
    """What a run file says about the run it belongs to."""
    run_id: str | None
    scene: str
    n_points: int
    every: int
    dt: float


def read_run_file(h5: Path) -> RunFile:
    import h5py
    try:
        with h5py.File(h5, "r") as f:
            a = f.attrs
            return RunFile(str(a["run_id"]) if "run_id" in a else None, str(a.get("scene", "")),
                           int(a.get("n_points", -1)), int(a.get("every", -1)),
                           float(a.get("dt", 0.0)))
    except (OSError, KeyError, ValueError) as e:
        raise RunDirError(f"{h5}: cannot read the run file ({e})") from None


def check_new_run(out: Path, overwrite: bool) -> None:
    """A new run into ``out``: refuse an existing run file unless ``overwrite``."""
    if out.exists() and not out.is_dir():
        raise RunDirError(f"--out {out} exists and is not a directory")
    h5 = out / RUN_FILE
    if h5.exists() and not overwrite:
        raise RunDirError(f"{h5} exists (use --overwrite to replace it, or another --out)")


#: where the run file's scene text ends and its --set overrides begin
OVERRIDES_MARK = "\n# overrides (--set)\n"


def check_restart(out: Path, ck_run_id: str | None, scene_text: str, n_points: int,
                  every: int, dt: float) -> None:
    """A restart from a checkpoint of run ``ck_run_id`` into ``out``: the run file
    there must be that run's (the same run id, scene TOML ``scene_text`` without
    overrides -- a restart may add some -- and point count ``n_points``), and the
    frame layout must stay: a restart may change the run length, not the frame
    spacing ``every`` or the step ``dt``, since frames are indexed by step // every."""
    if out.exists() and not out.is_dir():
        raise RunDirError(f"--out {out} exists and is not a directory")
    h5 = out / RUN_FILE
    if ck_run_id is None:
        raise RunDirError("the checkpoint has no run id (written by an older mpipd), so it "
                          f"cannot be matched to {h5}; rerun the scene")
    if not h5.exists():
        raise RunDirError(f"{h5} does not exist: a restart continues the run file of its run "
                          f"(run id {ck_run_id[:12]}); give --out the directory that holds it")
    rf = read_run_file(h5)
    if rf.run_id != ck_run_id:
        theirs = rf.run_id[:12] if rf.run_id else "none"
        raise RunDirError(f"{h5} belongs to another run (run id {theirs}, the checkpoint's is "
                          f"{ck_run_id[:12]}); restart into the checkpoint's own run directory")
    if rf.n_points != n_points or rf.scene.split(OVERRIDES_MARK)[0] != scene_text:
        raise RunDirError(f"{h5} has the checkpoint's run id but another scene or point count "
                          "(edited by hand?); refusing to write into it")
    if rf.every != every:
        raise RunDirError(f"a restart cannot change output.every ({rf.every} -> {every}): "
                          "the frames in the run file are indexed by step")
    if rf.dt != dt:
        raise RunDirError(f"a restart cannot change time.dt ({rf.dt:g} -> {dt:g} s)")


def ensure_writable(out: Path) -> None:
    """Create ``out`` (and parents) and check that a file can be made in it."""
    try:
        out.mkdir(parents=True, exist_ok=True)
        probe = out / f".mpipd-write-test-{os.getpid()}"
        with open(probe, "w") as f:
            f.write("x")
        probe.unlink()
    except OSError as e:
        raise RunDirError(f"cannot write to --out {out}: {e.strerror or e}") from None


def clear_old_run(out: Path) -> list[str]:
    """``--overwrite``: remove the replaced run's checkpoints and log; returns the names removed."""
    gone = []
    for name in OLD_RUN_FILES:
        p = out / name
        if p.exists():
            p.unlink()
            gone.append(name)
    return gone


_H5_REASON = re.compile(r"error message = '([^']+)'")


def io_reason(exc: BaseException) -> str:
    """The operating system's reason inside an OSError, h5py's included
    (h5py folds errno and message into a long string)."""
    if isinstance(exc, OSError) and exc.strerror:
        return exc.strerror
    text = str(exc)
    m = _H5_REASON.search(text)
    if m:
        return m.group(1)
    for code in (errno.ENOSPC, errno.EROFS, errno.EDQUOT, errno.EFBIG, errno.EACCES):
        msg = os.strerror(code)
        if msg in text:
            return msg
    return text.splitlines()[0] if text else type(exc).__name__


def io_cause(exc: BaseException) -> OSError | None:
    """The OSError behind ``exc``, itself or in its chain (h5py raises a
    RuntimeError when closing a file whose write failed); None if none."""
    seen = set()
    while exc is not None and id(exc) not in seen:
        if isinstance(exc, OSError):
            return exc
        seen.add(id(exc))
        exc = exc.__cause__ or exc.__context__
    return None


def describe_io(exc: OSError, out: Path) -> str:
    """One line: the reason, and the free space left where the run writes
    (HDF5's MPI-IO driver often reports only 'file write failed')."""
    reason = io_reason(exc)
    try:
        st = os.statvfs(out)
        free = st.f_bavail * st.f_frsize
        reason += f" ({free / 1e6:.3g} MB free on that file system)"
    except OSError:
        pass
    return f"cannot write in {out}: {reason}"


def io_line(exc: BaseException, out: Path) -> str | None:
    """:func:`describe_io` of the OSError behind ``exc`` (:func:`io_cause`); None
    if no OSError is behind it (then it is no file-system failure)."""
    cause = io_cause(exc)
    return None if cause is None else describe_io(cause, out)


class IOFailure(Fatal):
    """Writing a run's own file failed (disk full, read-only, quota): one line, exit 4."""
    exit_code = 4
