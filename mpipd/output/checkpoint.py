"""Checkpoint and restart: the complete state, indexed by global id.

A checkpoint holds everything the next step needs that cannot be recomputed
from it: u, v, a, the unrotated stress, R, V, strain energy, the fallback
flags, failure modes, every material history array (``points/state<material
id>/<name>``, on every rank, zeros where a rank has no point of that material), the broken bonds (as
(gid_i, gid_j) pairs), the gas's volume, pressure and energy, the loads' work,
the step and the time, and the scene text.  Shape tensors, F, damage phi, the damped set and the force data are
rebuilt from it deterministically.

Because every per-point dataset is indexed by gid and broken bonds by gid
pairs, a checkpoint written by N ranks restarts on M ranks, and the continued
run is bit-identical to the uninterrupted one (tests/test_restart.py).

Files are written collectively (h5py ``mpio``) to ``<name>.tmp`` and renamed
by rank 0 once complete, so a checkpoint on disk is never half written.
"""
from __future__ import annotations

import json
import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .. import __version__
from ..kernels.layout import GD_A, GD_P, GD_V

FORMAT = "mpipd-checkpoint-1"


class CheckpointError(ValueError):
    """A checkpoint file that cannot be used (missing, malformed, other scene)."""


def _per_point(sim) -> dict:
    """Owned-point arrays to save: name -> array (first axis = owned points)."""
    n = sim.points.n_owned
    c = sim.corr
    out = {"u": sim.u[:n], "v": sim.v[:n], "a": sim.a, "sigma": c.sigma, "R": c.R, "V": c.V,
           "W": c.W, "spring": c.spring, "mode": sim.mode[:n],
           # F of the last step, over the families after that step's breakage (the
           # next rotation increment needs it as it was, not recomputed), and the
           # volume factor that keeps J continuous across those rebuilds
           "F_old": c.F_old, "Jfac": c.Jfac}
    led = sim.ledger                              # the ledger's per-point memory
    if len(led.edamp):
        out["ledger_edamp"] = led.edamp
    if len(led.fv_old):
        out["ledger_fv_old"] = led.fv_old
    if sim.interface is not None:
        fc = np.zeros((n, 3))
        fc[sim.interface.idx] = led.fc_old
        out["ledger_fc_old"] = fc
    for key, arr in sim.peaks.arrays.items():
        if len(arr):
            out[key] = arr
    # material history by material id, the same names on every rank (the datasets are
    # created collectively): a material with no points here writes zeros
    here = {g.mid: g for g in c.groups}
    for mid, mat in enumerate(c.materials):
        g = here.get(mid)
        for key, arr in (g.state if g is not None else mat.new_state(0)).items():
            full = np.zeros((n,) + arr.shape[1:], arr.dtype)
            if g is not None:
                full[g.idx] = arr
            out[f"state{mid}/{key}"] = full
    if sim.gas is not None:                       # volume, pressure, energy of the gas
        gas = sim.gas
        out["gas_V"] = gas.gd[:n, GD_V]
        out["gas_p"] = gas.gd[:n, GD_P]
        out["gas_A"] = gas.gd[:n, GD_A:GD_V]             # the last force (its work ends next step)
        out["gas_Vw"] = gas.V_w[:n]               # the last step's pair weights
        e = np.zeros(n)
        e[gas.gas_idx] = gas.e
        out["gas_e"] = e
    return out


def _broken_pairs(sim) -> np.ndarray:
    fam, gid = sim.families, sim.points.gid
    rows = np.repeat(np.arange(sim.points.n_owned), np.diff(fam.offsets))
    b = fam.broken.astype(bool)
    return np.stack([gid[rows[b]], gid[fam.nbr[b]]], axis=1).astype(np.int64)


def write(sim, path, scene_text: str, overrides=(), run_id: str = "") -> Path:
    """Write the checkpoint of run ``run_id`` to ``path`` (collective).  If writing
    fails (a full disk), the partial ``<path>.tmp`` is removed and the error raised;
    an older checkpoint at ``path`` is untouched."""
    path = Path(path)
    tmp = path.with_name(path.name + ".tmp")
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


def _write(sim, tmp, scene_text, overrides, run_id):
    import h5py
    team = sim.team
    N = sim.n_global
    g0, g1 = sim.gid_range
    pairs = _broken_pairs(sim)
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
        a["external_work"] = team.sum(sim.external_work)
        led = sim.ledger
        for key, v in (("ledger_viscous_work", led.viscous_work),
                       ("ledger_interface_work", led.interface_work),
                       ("ledger_jumps", led.jumps),
                       ("ledger_contact_jumps", led.contact_jumps)):
            a[key] = team.sum(v)
        a["ledger_initial"] = led.initial
        a["bonds_broken"] = sim.bonds_broken()
        if sim.probes is not None:                # the running peaks, whole run
            a["probe_peaks"] = json.dumps(sim.probes.peaks())
        for name, arr in _per_point(sim).items():
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
            self.written = write(self.sim, self.path, self.scene_text, self.overrides,
                                 self.run_id)

    def after_step(self) -> bool:
        """Checkpoint if due; True if the run should stop now."""
        step = self.sim.step_count
        stop = self.stop_after is not None and step >= self.stop_after
        if not stop and step % self.poll == 0:
            stop = bool(self.sim.team.max(int(self.signalled)))
        if stop or (self.every and step % self.every == 0):
            self.written = write(self.sim, self.path, self.scene_text, self.overrides,
                                 self.run_id)
        return stop


def restore(sim, path) -> None:
    """Load a checkpoint into a freshly built Simulation of the same scene."""
    import h5py
    team = sim.team
    n = sim.points.n_owned
    g0, g1 = sim.gid_range
    with h5py.File(path, "r", driver="mpio", comm=team.comm) as f:
        if f.attrs.get("format") != FORMAT or int(f.attrs["n_points"]) != sim.n_global:
            raise CheckpointError(f"{path}: checkpoint does not match this scene")
        data = {}
        for name, arr in _per_point(sim).items():
            if f"points/{name}" not in f:
                raise CheckpointError(f"{path}: checkpoint lacks points/{name}")
            data[name] = f[f"points/{name}"][g0:g1]
        broken = f["broken"]
        gi = broken[:, 0] if len(broken) else np.empty(0, np.int64)
        lo, hi = np.searchsorted(gi, g0, "left"), np.searchsorted(gi, g1, "left")
        mine = broken[lo:hi] if hi > lo else np.empty((0, 2), np.int64)
        step, t = int(f.attrs["step"]), float(f.attrs["t"])
        work = float(f.attrs["external_work"])
        ledger = {k: float(f.attrs[k]) for k in ("ledger_viscous_work", "ledger_interface_work",
                                                 "ledger_jumps", "ledger_contact_jumps",
                                                 "ledger_initial")}
        n_broken = int(f.attrs["bonds_broken"])
        probe_peaks = json.loads(str(f.attrs["probe_peaks"])) if "probe_peaks" in f.attrs else {}
    bad = [name for name, arr in data.items()
           if arr.dtype.kind == "f" and not np.all(np.isfinite(arr))]
    bad = sorted(set().union(*team.gather(set(bad))))
    if bad or not all(np.isfinite(v) for v in (t, work, *ledger.values())):
        raise CheckpointError(f"{path}: non-finite values in " + (", ".join(bad) or "attributes")
                              + " (a corrupted checkpoint, or one written by a blow-up)")
    c = sim.corr
    sim.u[:n], sim.v[:n], sim.a[:] = data["u"], data["v"], data["a"]
    c.sigma[:], c.R[:], c.V[:], c.W[:] = data["sigma"], data["R"], data["V"], data["W"]
    sim.mode[:n] = data["mode"]
    for g in c.groups:
        for key, arr in g.state.items():
            arr[:] = data[f"state{g.mid}/{key}"][g.idx]
    # broken bonds by gid pair
    fam, gid = sim.families, sim.points.gid
    if len(mine):
        rows = np.repeat(np.arange(n), np.diff(fam.offsets))
        key = gid[rows] * sim.n_global + gid[fam.nbr]
        want = np.sort(mine[:, 0] * sim.n_global + mine[:, 1])
        fam.broken[:] = np.isin(key, want).astype(np.uint8)
    if sim.gas is not None:
        gas = sim.gas
        gas.gd[:n, GD_V], gas.gd[:n, GD_P] = data["gas_V"], data["gas_p"]
        gas.gd[:n, GD_A:GD_V] = data["gas_A"]
        gas.V_w[:n] = data["gas_Vw"]
        sim.halo.exchange(gas.V_w)
        gas.e[:] = data["gas_e"][gas.gas_idx]
        gas.V_ratio[gas.gas_idx] = gas.V_w[gas.gas_idx] / gas.V0
    sim.step_count, sim.t = step, t
    sim.external_work = work if team.root else 0.0
    # rebuild what follows from the state
    c.rebuild_shape()
    c.spring[:] = data["spring"]
    if sim.failure is not None:
        fl = sim.failure
        fl.bonds_broken = n_broken if team.root else 0      # a global count, held once
        sim.halo.exchange(fl.mode)
        fl.done[:] = fl.mode != 0
        fl.refresh_damage()
        if sim.interface is not None:       # retired where bonds broke or families failed
            sim.interface.retire(sim.mode)
    led = sim.ledger
    own = team.root                                 # global sums, held once
    led.viscous_work = ledger["ledger_viscous_work"] if own else 0.0
    led.interface_work = ledger["ledger_interface_work"] if own else 0.0
    led.jumps = ledger["ledger_jumps"] if own else 0.0
    led.contact_jumps = ledger["ledger_contact_jumps"] if own else 0.0
    led.initial = ledger["ledger_initial"]
    if len(led.edamp):
        led.edamp[:] = data["ledger_edamp"]
    for key, arr in sim.peaks.arrays.items():
        if len(arr):
            arr[:] = data[key]
    c.Jfac[:] = data["Jfac"]
    if sim.probes is not None:
        sim.probes.restore_peaks(probe_peaks)
    sim.initialize()
    sim.a[:] = data["a"]
    c.F_old[:] = data["F_old"]
    if len(led.fv_old):
        led.fv_old[:] = data["ledger_fv_old"]
    if sim.interface is not None:
        led.fc_old[:] = data["ledger_fc_old"][sim.interface.idx]
