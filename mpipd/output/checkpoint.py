"""Checkpoint and restart: the complete state, indexed by global id.

A checkpoint holds everything the next step needs that cannot be recomputed
from it: every field of the State registered with ``checkpoint=True``
(``points/<name>``: u, v, a, the unrotated stress, R, V, stress work, the
fallback codes, failure modes, F of the last step, the volume factor, every
material history array as ``points/state<material id>/<name>`` on every rank
(zeros where a rank has no point of that material), the gas's volume,
pressure, force state, pair weights and energy, the ledger's per-point memory,
the running peaks), every registered scalar as an attribute (the loads' work,
the ledger's sums, the broken-bond count), the broken bonds (as (gid_i, gid_j)
pairs), the probes' running peaks, the step and the time, and the scene text.
Shape tensors, F, damage phi, the damped set and the force data are rebuilt
from it deterministically; :func:`restore` lists the order (mpipd.state).

Because every per-point dataset is indexed by gid and broken bonds by gid
pairs, a checkpoint written by N ranks restarts on M ranks, and the continued
run is bit-identical to the uninterrupted one (tests/test_restart.py).

Every checkpoint carries checksums (attribute ``checksums``, JSON: one per
``points/<name>`` dataset, one for ``broken`` and one for the step, time and
scalar attributes; mpipd.kernels.hashrng.row_checksum, a sum over gid-keyed rows,
so the same on any number of ranks), computed from the arrays as they are
written and verified on restart: a checkpoint changed after it was written
(finite garbage the non-finite test cannot see) is refused with one line
(CheckpointError, exit 2) instead of running on from it and blaming dt later.  A
checkpoint written before the checksums (none stored) is restored with a warning
in the run log that its data are not verified.

Files are written collectively (h5py ``mpio``) to ``<name>.tmp`` and renamed
by rank 0 once complete, so a checkpoint on disk is never half written.  Before
any of it is written, rank 0 compares the checkpoint's data size with the space
free where it goes and every rank refuses together when it does not fit: a write
that fails on one rank in the middle of a collective call leaves the others
waiting in the next one.
"""
from __future__ import annotations

import errno
import json
import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .. import __version__
from ..kernels.hashrng import row_checksum
from ..state import LAST, REBUILT, STATE
from .pairs import rows_between

FORMAT = "mpipd-checkpoint-1"


class CheckpointError(ValueError):
    """A checkpoint file that cannot be used (missing, malformed, other scene)."""


#: the attribute holding the checksums, and what they are
CHECKSUMS = "checksums"
CHECKSUM_KIND = "mpipd.kernels.hashrng.row_checksum by gid (points/*), by gid_i (broken)"


def _salt(name: str) -> int:
    import hashlib
    return int.from_bytes(hashlib.blake2b(name.encode(), digest_size=8).digest(), "little")


def _attr_token(v) -> str:
    """A scalar attribute as the checksum sees it (exact: ints as ints, floats in hex)."""
    return (str(int(v)) if np.issubdtype(np.asarray(v).dtype, np.integer)
            else float(v).hex())


def _checksums(team, data: dict, g0: int, pairs: np.ndarray, attrs: dict) -> dict:
    """Checksums (hex) of the whole checkpoint from this rank's rows (collective):
    ``data`` (name -> owned rows, gids g0...), its broken ``pairs`` and the
    scalar ``attrs`` (the same on every rank)."""
    mine = {f"points/{name}": row_checksum(arr, np.arange(g0, g0 + len(arr)),
                                           _salt(f"points/{name}"))
            for name, arr in data.items()}
    mine["broken"] = row_checksum(pairs, pairs[:, 0] if len(pairs) else np.empty(0),
                                  _salt("broken"))
    parts = team.gather(mine)
    out = {k: f"{sum(p[k] for p in parts) % 2 ** 64:016x}" for k in mine}
    tokens = np.array([_salt(f"{k}={_attr_token(attrs[k])}") for k in sorted(attrs)],
                      np.uint64)
    out["attrs"] = f"{row_checksum(tokens, np.arange(len(tokens)), _salt('attrs')):016x}"
    return out


def _per_point(sim) -> dict:
    """Owned-point arrays to save: name -> array (first axis = owned points), every
    checkpointed field of the State (mpipd.state)."""
    n = sim.points.n_owned
    return {f.name: f.owned_values(n) for f in sim.state.checkpointed()}


def write(sim, path, scene_text: str, overrides=(), run_id: str = "") -> Path:
    """Write the checkpoint of run ``run_id`` to ``path`` (collective).  If writing
    fails (a full disk), the partial ``<path>.tmp`` is removed and the error raised;
    an older checkpoint at ``path`` is untouched."""
    path = Path(path)
    tmp = path.with_name(path.name + ".tmp")
    _check_room(sim, path.parent, scene_text)
    try:
        _write(sim, tmp, scene_text, overrides, run_id)
    except BaseException:
        try:
            tmp.unlink()
        except OSError:
            pass
        raise
    team = sim.team
    team.barrier()
    if team.root:
        os.replace(tmp, path)
    team.barrier()
    return path


#: what a checkpoint holds besides its data (HDF5 headers, attributes), bytes
OVERHEAD = 64 * 1024


def _check_room(sim, where: Path, scene_text: str):
    """Raise ENOSPC on every rank (collective) when the checkpoint's data (the
    per-point datasets, the broken pairs and the scene text, plus OVERHEAD) exceed
    the space free at ``where``, as rank 0 sees it."""
    team = sim.team
    n = sim.n_global
    need = sum(n * a[:1].nbytes for a in _per_point(sim).values() if len(a)) if n else 0
    need = team.max(need) + 16 * team.sum(int(np.count_nonzero(sim.families.broken))) \
        + len(scene_text.encode()) + OVERHEAD
    free = None
    if team.root:
        st = os.statvfs(where)
        free = st.f_bavail * st.f_frsize
    free = team.bcast(free)
    if need > free:
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC),
                      f"{where}: a checkpoint needs about {need / 1e6:.3g} MB")


def _write(sim, tmp, scene_text, overrides, run_id):
    import h5py
    team = sim.team
    N = sim.n_global
    g0, g1 = sim.gid_range
    pairs = sim.families.broken_pairs(sim.points.gid)
    counts = team.gather(len(pairs))
    p0 = int(sum(counts[:team.rank]))
    total = int(sum(counts))
    with h5py.File(tmp, "w", driver="mpio", comm=team.comm) as f:
        a = f.attrs
        a["format"] = FORMAT
        a["run_id"] = run_id
        a["mpipd_version"] = __version__
        a["scene"] = scene_text
        a["overrides"] = json.dumps(list(overrides))
        a["step"] = sim.step_count
        a["t"] = sim.t
        a["n_points"] = N
        a["ranks"] = team.size
        checked = {"step": sim.step_count, "t": sim.t}
        for s in sim.state.scalars.values():    # loads' work, ledger sums, broken bonds
            a[s.name] = checked[s.name] = ({"sum": team.sum, "max": team.max}[s.reduce](s.get())
                                           if s.reduce in ("sum", "max") else s.get())
        if sim.probes is not None:                # the running peaks, whole run
            a["probe_peaks"] = json.dumps(sim.probes.peaks())
        data = _per_point(sim)
        a[CHECKSUMS] = json.dumps(_checksums(team, data, g0, pairs, checked))
        a["checksum_kind"] = CHECKSUM_KIND
        for name, arr in data.items():
            d = f.create_dataset(f"points/{name}", (N,) + arr.shape[1:], arr.dtype)
            with d.collective:
                d[g0:g1] = arr
        d = f.create_dataset("broken", (total, 2), "i8")
        # independent I/O: h5py skips the write call for an empty selection, so a
        # collective write hangs every other rank when one rank has no broken bond
        if len(pairs):
            d[p0:p0 + len(pairs)] = pairs


@dataclass(frozen=True)
class Info:
    """What a checkpoint says about itself (mpipd.output.rundir matches it to a run file)."""
    scene: str
    overrides: list
    step: int
    n_points: int
    run_id: str | None


def read_scene(path) -> Info:
    """The scene TOML, overrides, step, point count and run id stored in a
    checkpoint (serial read, any rank)."""
    import h5py

    from .rundir import io_reason
    if not Path(path).is_file():
        raise CheckpointError(f"{path}: no such checkpoint file")
    try:
        with h5py.File(path, "r") as f:
            if f.attrs.get("format") != FORMAT:
                raise CheckpointError(f"{path}: not an mpipd checkpoint")
            a = f.attrs
            return Info(str(a["scene"]), json.loads(str(a["overrides"])), int(a["step"]),
                        int(a["n_points"]), str(a["run_id"]) if a.get("run_id") else None)
    except (OSError, KeyError, ValueError) as e:
        raise CheckpointError(f"{path}: cannot read checkpoint ({io_reason(e)})") from None


class SignalFlag:
    """Records SIGTERM/SIGUSR1 (what batch systems send before the wall-time
    kill) instead of dying.  `mpipd run` installs it first thing, before the
    model is built, so an early warning is never fatal; it stays installed to
    the end, so a late one is harmless."""

    def __init__(self):
        import signal
        self.seen = False
        for sig in (signal.SIGTERM, signal.SIGUSR1):
            signal.signal(sig, self._set)

    def _set(self, signum, frame):
        self.seen = True


class Checkpointer:
    """Decides after each step whether to checkpoint, and whether to stop.

    * every ``every`` steps (0: never);
    * at step ``stop_after``, then stop;
    * when SIGTERM or SIGUSR1 arrived on any rank (what batch systems send
      before the wall-time kill), then stop — ranks agree through a reduction
      every ``poll`` steps.
    """

    def __init__(self, sim, path, scene_text, overrides=(), every=0, stop_after=None, poll=10,
                 run_id: str = ""):
        self.sim = sim
        self.run_id = run_id
        self.path = Path(path)
        self.scene_text = scene_text
        self.overrides = list(overrides)
        self.every = every
        self.stop_after = stop_after
        self.poll = poll
        self._flag = None
        self.signalled = False
        self.written = None
        self.written_step = None     # the step of the last checkpoint this invocation wrote

    def install_signals(self, flag: "SignalFlag | None" = None):
        """Stop at the next poll once SIGTERM/SIGUSR1 arrived — from now on, or,
        given a :class:`SignalFlag` installed earlier, since then."""
        self._flag = flag or SignalFlag()

    @property
    def signalled(self) -> bool:
        return self._signalled or (self._flag is not None and self._flag.seen)

    @signalled.setter
    def signalled(self, value: bool):
        self._signalled = bool(value)

    def write_final(self):
        """A last checkpoint for inspection (after a failure), beside the regular one."""
        self.written = write(self.sim, self.path.with_name("checkpoint_failed.h5"),
                             self.scene_text, self.overrides, self.run_id)

    def at_end(self):
        """The last step's checkpoint, when checkpoints were asked for: a finished
        run can then be extended (``--restart ... --set time.t_end=...``)."""
        if self.every:
            self._write()

    def after_step(self) -> bool:
        """Checkpoint if due; True if the run should stop now."""
        step = self.sim.step_count
        stop = self.stop_after is not None and step >= self.stop_after
        if not stop and step % self.poll == 0:
            stop = bool(self.sim.team.max(int(self.signalled)))
        if stop or (self.every and step % self.every == 0):
            self._write()
        return stop

    def _write(self):
        self.written = write(self.sim, self.path, self.scene_text, self.overrides, self.run_id)
        self.written_step = self.sim.step_count


def restore(sim, path) -> str | None:
    """Load a checkpoint into a freshly built Simulation of the same scene; a
    checkpoint whose data do not match its checksums is refused (CheckpointError).
    Returns a warning for the run log (a checkpoint without checksums), else None."""
    import h5py
    team = sim.team
    g0, g1 = sim.gid_range
    with h5py.File(path, "r", driver="mpio", comm=team.comm) as f:
        if f.attrs.get("format") != FORMAT or int(f.attrs["n_points"]) != sim.n_global:
            raise CheckpointError(f"{path}: checkpoint does not match this scene")
        data = {}
        for name in (fld.name for fld in sim.state.checkpointed()):
            if f"points/{name}" not in f:
                raise CheckpointError(f"{path}: checkpoint lacks points/{name}")
            data[name] = f[f"points/{name}"][g0:g1]
        mine = rows_between(f["broken"], 0, len(f["broken"]), g0, g1)
        step, t = int(f.attrs["step"]), float(f.attrs["t"])
        scalars = {}
        for name in sim.state.scalars:
            if name not in f.attrs:
                raise CheckpointError(f"{path}: checkpoint lacks attribute {name}")
            v = f.attrs[name]
            scalars[name] = int(v) if np.issubdtype(np.asarray(v).dtype, np.integer) else float(v)
        probe_peaks = json.loads(str(f.attrs["probe_peaks"])) if "probe_peaks" in f.attrs else {}
        try:
            stored = json.loads(str(f.attrs[CHECKSUMS])) if CHECKSUMS in f.attrs else None
        except ValueError:
            stored = {}
    bad = [name for name, arr in data.items()
           if arr.dtype.kind == "f" and not np.all(np.isfinite(arr))]
    bad = sorted(set().union(*team.gather(set(bad))))
    if bad or not all(np.isfinite(v) for v in (t, *scalars.values())):
        raise CheckpointError(f"{path}: non-finite values in " + (", ".join(bad) or "attributes")
                              + " (a corrupted checkpoint, or one written by a blow-up)")
    note = None
    if stored is None:
        note = (f"{path} carries no checksums (written by an mpipd before they were "
                "added): its data are restored unverified")
    else:
        now = _checksums(team, data, g0, mine, {"step": step, "t": t, **scalars})
        wrong = [k for k in now if stored.get(k) != now[k]]
        if wrong:
            raise CheckpointError(f"{path}: {', '.join(wrong[:3])}"
                                  + (f" and {len(wrong) - 3} more" if len(wrong) > 3 else "")
                                  + (" does not match the checksum written with it"
                                     if len(wrong) == 1 else
                                     " do not match the checksums written with them")
                                  + " (the file changed after it was written: a corrupted "
                                  "checkpoint)")
    st = sim.state
    for fld in st.checkpointed(STATE):                  # 1. the state
        fld.load(data[fld.name])
    missing = sim.families.set_broken(sim.points.gid, mine)   # broken bonds by gid pair
    if team.max(missing):
        raise CheckpointError(f"{path}: broken bonds that are not bonds of this scene's "
                              "families (a checkpoint of another model)")
    sim.step_count, sim.t = step, t
    for name, s in st.scalars.items():                  # global sums: held once, on rank 0
        v = scalars[name]
        s.set(v if s.reduce in ("same", "max") or team.root else type(v)(0))
    sim.after_restore()                                 # 2. what follows from it
    for fld in st.checkpointed(REBUILT):                # 3. saved over the rebuild
        fld.load(data[fld.name])
    if sim.probes is not None:
        sim.probes.restore_peaks(probe_peaks)
    sim.initialize()                                    # 4. F and forces
    for fld in st.checkpointed(LAST):                   # 5. the last step's values
        fld.load(data[fld.name])
    return note
