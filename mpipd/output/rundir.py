"""The run directory: which files belong to a run, and who may write them.

A run directory ``OUT`` holds one run's files::

    OUT/run.h5              the run file (mpipd.output.writer), attribute ``run_id``
    OUT/run.xdmf            its ParaView index
    OUT/run.log             the log (appended to by restarts)
    OUT/checkpoint.h5       the last checkpoint (mpipd.output.checkpoint), attribute ``run_id``
    OUT/checkpoint_failed.h5  the state at a blow-up
    OUT/run.lock            held (flock) by the run's rank 0 for the run's whole life

A run folder holds one live run at a time: rank 0 takes an exclusive ``flock``
on ``OUT/run.lock`` before it writes anything (:class:`RunLock`) and keeps it to
the end; a second run or a restart into the folder meanwhile is refused (exit 2,
one line naming the holder's pid and host).  The kernel drops the lock when its
process dies, however it dies, so a lock file left by a killed job is stale and
the next run takes it over.

A restart continues the same physics (mpipd.input.restart): only the run length,
the checkpoint and progress cadence and the ledger's stop bound may change; it
never rewrites a frame it does not write again (:func:`check_frames`).

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
import fcntl
import json
import os
import re
import socket
import time
import uuid
from dataclasses import dataclass
from pathlib import Path

RUN_FILE = "run.h5"
CHECKPOINT = "checkpoint.h5"
LOCK = "run.lock"
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
    steps: int = -1              # the run length the file is sized for
    frames_written: int = 0
    n_alloc: int = 0             # frames the file has room for (/time's length)

    @property
    def finished(self) -> bool:
        return self.n_alloc > 0 and self.frames_written == self.n_alloc

    def frame_step(self, k: int) -> int:
        """The step of frame ``k``: every ``every`` steps, the last at ``steps``."""
        return min(k * self.every, self.steps)

    @property
    def last_step_written(self) -> int:
        return self.frame_step(self.frames_written - 1) if self.frames_written > 0 else -1


def read_run_file(h5: Path) -> RunFile:
    import h5py
    try:
        with h5py.File(h5, "r") as f:
            a = f.attrs
            return RunFile(str(a["run_id"]) if "run_id" in a else None, str(a.get("scene", "")),
                           int(a.get("n_points", -1)), int(a.get("every", -1)),
                           float(a.get("dt", 0.0)), int(a.get("steps", -1)),
                           int(a.get("frames_written", 0)),
                           int(f["time"].shape[0]) if "time" in f else 0)
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
                  every: int, dt: float, ck_step: int | None = None,
                  n_steps: int | None = None) -> bool:
    """A restart from a checkpoint of run ``ck_run_id`` into ``out``: the run file
    there must be that run's (the same run id, scene TOML ``scene_text`` without
    overrides -- a restart may add some -- and point count ``n_points``), and the
    frame layout must stay: a restart may change the run length, not the frame
    spacing ``every`` or the step ``dt``, since frames are indexed by step // every.
    Given the checkpoint's step and the new run length, also :func:`check_frames`;
    returns True when the run is finished at that length (nothing to do)."""
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
    if ck_step is None or n_steps is None:
        return False
    return check_frames(rf, ck_step, n_steps, every)


def check_frames(rf: RunFile, ck_step: int, n_steps: int, every: int) -> bool:
    """A restart from step ``ck_step`` with run length ``n_steps`` into run file
    ``rf``: refuse (RunDirError) one that would drop or overwrite a frame the file
    holds and the restart does not write again -- a frame after the new end, or an
    off-cadence last frame (a finished run's step that is no multiple of ``every``)
    whose row a longer run gives another step.  Returns True when there is nothing
    to do: the file is finished at exactly this run length and the checkpoint is at
    its end (the restart then writes nothing)."""
    last = rf.last_step_written
    if n_steps == ck_step:
        if rf.finished and rf.steps == n_steps:
            return True
        raise RunDirError(f"the run length ({n_steps} steps) ends at the checkpoint's step "
                          f"{ck_step}: nothing to run (set a longer time.t_end or time.steps)")
    if last > n_steps:
        raise RunDirError(f"the run file holds frames to step {last}; a run length of {n_steps} "
                          "steps would drop them (set time.t_end or time.steps to reach it)")
    if last >= 0 and last % every and last != n_steps:
        raise RunDirError(f"the run file's last frame is at step {last}, off the output.every = "
                          f"{every} cadence (the end of a run of {rf.steps} steps); a run of "
                          f"{n_steps} steps would write step {last - last % every + every}'s "
                          "frame into its row (frames are indexed by step // every): to extend "
                          f"a run later, give it a run length that is a multiple of {every}")
    return False


class RunLock:
    """An exclusive ``flock`` on ``OUT/run.lock``, held by rank 0 from before the
    run's first write to its end.  The file names its holder (pid, host, time).
    The kernel releases a flock when its process dies, so a lock left by a killed
    run is free; :meth:`release` unlinks the file while still holding it, and
    :meth:`acquire` checks that the file it locked is still the one at the path (a
    process that opened the old file just before the unlink must not think it
    holds a lock)."""

    def __init__(self, out: Path):
        self.path = Path(out) / LOCK
        self.fd = None
        self.made_dir = False

    def acquire(self) -> "RunLock":
        out = self.path.parent
        if out.exists() and not out.is_dir():
            raise RunDirError(f"--out {out} exists and is not a directory")
        try:
            if not out.exists():
                out.mkdir(parents=True)
                self.made_dir = True
            for _ in range(20):
                fd = os.open(self.path, os.O_RDWR | os.O_CREAT, 0o644)
                try:
                    fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
                except BlockingIOError:
                    holder = self._holder(fd)
                    os.close(fd)
                    raise RunDirError(f"{out} is in use by another mpipd run ({holder}); one "
                                      "run per folder: wait for it, or use another --out") from None
                try:
                    same = os.fstat(fd).st_ino == os.stat(self.path).st_ino
                except FileNotFoundError:
                    same = False
                if same:
                    self.fd = fd
                    break
                os.close(fd)                 # unlinked by its holder meanwhile: again
            else:
                raise RunDirError(f"cannot take the lock {self.path} (it keeps changing)")
            os.ftruncate(self.fd, 0)
            os.write(self.fd, json.dumps({"pid": os.getpid(), "host": socket.gethostname(),
                                          "since": time.strftime("%Y-%m-%d %H:%M:%S")}).encode())
            os.fsync(self.fd)
        except OSError as e:
            self._undo()
            raise RunDirError(f"cannot write to --out {out}: {e.strerror or e}") from None
        return self

    @staticmethod
    def _holder(fd) -> str:
        try:
            d = json.loads(os.pread(fd, 4096, 0).decode() or "{}")
            return f"pid {d['pid']} on {d['host']} since {d['since']}"
        except (OSError, ValueError, KeyError, TypeError):
            return "its lock file names no holder yet"

    def _undo(self):
        self.release(remove_dir=True)

    def release(self, remove_dir: bool = False):
        """Unlink the lock file and drop the lock; ``remove_dir``: also remove the
        folder if this run made it and it is empty (a run refused before writing)."""
        if self.fd is not None:
            try:
                os.unlink(self.path)
            except OSError:
                pass
            os.close(self.fd)
            self.fd = None
        if remove_dir and self.made_dir:
            try:
                self.path.parent.rmdir()
            except OSError:
                pass


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
