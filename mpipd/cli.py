"""Command line: ``mpipd run | check | scenes | cases`` (:data:`USAGE`).

    mpirun -n 2 mpipd run SCENE [--set key.path=value ...] [--out DIR] [--overwrite]
                              [--force] [--stop-after N]
    mpirun -n 3 mpipd run --restart DIR/checkpoint.h5 [--out DIR]
    mpipd check SCENE [--ranks N] [--set ...]
    mpipd scenes [--show SCENE]     (--show: its TOML and where it lives)
    mpipd cases SCENE               (then run SCENE:CASE)

SCENE is a TOML file or the name of a built-in scene.  Bad input (scene
errors, an existing output file, a decomposition that cannot work, a corrupted
checkpoint, and an --out that cannot be written at the start -- read-only, no
permission -- which rundir.ensure_writable tries before the run's first write)
prints one line ``mpipd: error: <what>`` on rank 0 and exits with status 2 on
every rank, before anything is written.  A run writes only its own files
(mpipd.output.rundir: run ids, the restart and --overwrite rules).  A file of the
run that cannot be written once the run has begun writing (disk full, a file
system gone read-only) prints one line and exits with status 4 (a finished run
whose end checkpoint fails prints its summary first, and that its run file is
complete); a blow-up exits with 3; a clean stop with a checkpoint
(--stop-after, SIGTERM or SIGUSR1) with 0.  Any other exception on any rank
prints its traceback and aborts the whole MPI job, so nothing hangs.
"""
from __future__ import annotations

import argparse
import os
import shlex
import socket
import sys
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from .kernels.layout import MODE_NAMES, N_MODES
from .parallel.team import Fatal

EXIT_BAD_INPUT = 2
EXIT_UNSTABLE = 3
EXIT_IO = 4          # a run's own file could not be written (disk full, read-only)


class UsageError(Exception):
    """Bad input that is not a scene key (output exists, too many ranks, …)."""


class IOFailure(Fatal):
    """Writing a run's own file failed (disk full, read-only, quota): one line, exit 4."""
    exit_code = EXIT_IO


#: ``mpipd --help``'s text (plain, not reStructuredText): every subcommand with its usage
DESCRIPTION = "mpipd: an MPI-parallel peridynamics solver for rock blasting."
USAGE = """\
commands:
  mpirun -n 2 mpipd run SCENE [--set KEY=VALUE ...] [--out DIR] [--overwrite]
                                 run a scene on 2 ranks (without mpirun: 1 rank)
  mpirun -n 3 mpipd run --restart DIR/checkpoint.h5
                                 continue a run from its checkpoint, on any number of ranks
  mpipd check SCENE [--ranks N]  validate a scene; sizes, memory per rank, the stable dt
  mpipd scenes                   list the built-in scenes
  mpipd scenes --show SCENE      print a built-in scene's TOML and where it lives
                                 (copy one: mpipd scenes --show blast_demo > my_blast.toml)
  mpipd cases SCENE              list a built-in scene's named cases (run SCENE:CASE)

SCENE is a TOML file, the name of a built-in scene, or SCENE:CASE.  KEY is a dotted
path into the scene, array entries by number: --set parts.1.dx=5e-4.
`mpipd COMMAND --help` gives a command's options.  Exit status: 0 done, 2 bad input
(one line 'mpipd: error: ...'), 3 the run blew up, 4 a run file could not be written.
Under mpirun as root, Open MPI needs OMPI_ALLOW_RUN_AS_ROOT=1 and
OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 (and OMPI_MCA_rmaps_base_oversubscribe=1 for more
ranks than cores)."""


def _parser() -> argparse.ArgumentParser:
    ap = argparse.ArgumentParser(prog="mpipd", description=DESCRIPTION, epilog=USAGE,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = ap.add_subparsers(dest="cmd", required=True)
    r = sub.add_parser("run", help="run a scene (under mpirun for several ranks)")
    r.add_argument("scene", nargs="?", help="scene file or built-in name (not with --restart)")
    r.add_argument("--restart", metavar="CHECKPOINT",
                   help="continue from a checkpoint (any number of ranks)")
    r.add_argument("--stop-after", type=int, default=None, metavar="STEP",
                   help="write a checkpoint at this step and stop")
    r.add_argument("--force", action="store_true",
                   help="run even if dt exceeds the stable estimate")
    r.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                   help="override a scene value, e.g. --set time.steps=100")
    r.add_argument("--out", default=None, help="output directory (default runs/<scene name>)")
    r.add_argument("--overwrite", action="store_true", help="replace an existing run.h5")
    r.add_argument("--force-size", action="store_true",
                   help="run even if the run file's size or the model's memory, estimated "
                        "before anything is built, exceeds the free disk space or memory")
    r.add_argument("--quiet", action="store_true", help="no progress lines")
    c = sub.add_parser("check", help="validate a scene and report sizes and the stable dt")
    c.add_argument("scene")
    c.add_argument("--ranks", type=int, default=1)
    c.add_argument("--set", action="append", default=[], metavar="KEY=VALUE")
    s = sub.add_parser("scenes", help="list the built-in scenes (--show SCENE: its TOML)")
    s.add_argument("--show", metavar="SCENE",
                   help="print a built-in scene's TOML and where it lives; SCENE:CASE adds "
                        "the case's overrides")
    k = sub.add_parser("cases", help="list the named cases of a built-in scene (run SCENE:CASE)")
    k.add_argument("scene")
    return ap


def main(argv=None) -> int:
    args = _parser().parse_args(argv)
    if args.cmd == "scenes":
        return _guard_serial(cmd_show, args) if args.show else cmd_scenes()
    if args.cmd == "cases":
        return _guard_serial(cmd_cases, args)
    if args.cmd == "check":
        return _guard_serial(cmd_check, args)
    return cmd_run(args)


def _error(msg: str) -> int:
    print(f"mpipd: error: {msg}", file=sys.stderr, flush=True)
    return EXIT_BAD_INPUT


def _guard_serial(fn, args) -> int:
    from .input.schema import SceneError
    from .parallel.decomp import DecompositionError
    try:
        return fn(args)
    except (SceneError, DecompositionError, UsageError) as e:
        return _error(str(e))


# ----------------------------------------------------------------------------- scenes

def cmd_scenes() -> int:
    from .input import scene as sc
    for name, path in sorted(sc.builtin_scenes().items()):
        try:
            desc = sc.load(str(path))[0].scene.description
        except Exception as e:   # a broken built-in is still listed
            desc = f"(invalid: {e})"
        print(f"{name:24s} {desc}")
    print(f"\n(files in {sc.scenes_dir()}; print one: mpipd scenes --show NAME; "
          f"its cases: mpipd cases NAME)")
    return 0


def cmd_show(args) -> int:
    """``mpipd scenes --show SCENE[:CASE]``: the built-in scene's TOML as it is in its
    file, headed by comment lines that say where it lives (so the output, redirected to
    a file, is the same scene); for SCENE:CASE the comments also give the case's file,
    description and overrides as ``--set`` options, to run the copy as the case."""
    from .input import scene as sc
    name, _, case = args.show.partition(":")
    builtins = sc.builtin_scenes()
    if name not in builtins:
        raise UsageError(f"no built-in scene {name!r} (built-in: {', '.join(sorted(builtins))})")
    path = builtins[name]
    head = [f"# built-in scene {name}: {path}"]
    if case:
        known = sc.cases(name)
        if case not in known:
            raise UsageError(f"no case {case!r} of {name!r} "
                             f"(cases: {', '.join(known) if known else 'none'})")
        c = known[case]
        head += [f"# case {name}:{case} ({sc.cases_dir() / (name + '.toml')}): {c.description}",
                 f"# the case is this scene with the overrides below "
                 f"(mpipd run {name}:{case}, or mpipd run COPY.toml with them):"]
        head += [f"#   --set {shlex.quote(o)}" for o in c.set]
    print("\n".join(head))
    print(path.read_text(encoding="utf-8-sig"), end="")
    return 0


def cmd_cases(args) -> int:
    """One line a case: ``SCENE:CASE``, its study and what it changes."""
    from .input import scene as sc
    if args.scene not in sc.builtin_scenes():
        raise UsageError(f"no built-in scene {args.scene!r}")
    for name, case in sc.cases(args.scene).items():
        print(f"{args.scene}:{name:8s} {case.study:15s} {case.description}")
    return 0


# ----------------------------------------------------------------------------- check

def cmd_check(args) -> int:
    from .check import check_report
    from .input import scene as sc
    if args.ranks < 1:
        raise UsageError(f"--ranks must be >= 1 (got {args.ranks})")
    scene, _ = sc.load(args.scene, args.set)
    print(check_report(scene, args.ranks))
    from .check import critical_dt
    dt_max = critical_dt(scene)
    if scene.time.dt > dt_max:
        print(f"mpipd: error: dt = {scene.time.dt:.4e} s is above the stable step "
              f"{dt_max:.4e} s: the run will be unstable (mpipd run refuses it without "
              "--force; lower time.dt)", file=sys.stderr)
        return EXIT_BAD_INPUT
    return 0


# ----------------------------------------------------------------------------- run

def cmd_run(args) -> int:
    from .output.checkpoint import SignalFlag
    signals = SignalFlag()         # first: a batch system's early warning must not kill the run
    os.environ.setdefault("OMPI_MCA_rmaps_base_oversubscribe", "1")
    from .parallel.team import abort_on_error, world
    team = world()
    return abort_on_error(team, _run, args, team, signals)


def _bad_input(team, exc) -> int:
    if team.root:
        _error(str(exc))
    return EXIT_BAD_INPUT


def _run(args, team, signals=None) -> int:
    from .input import scene as sc
    from .input.geometry import check_parts
    from .input.restart import check_same_physics
    from .input.schema import SceneError
    from .model.gas import check_charges
    from .model.stability import critical_dt
    from .output import checkpoint as ck
    from .output import rundir
    from .parallel.decomp import DecompositionError
    from .solver import Simulation

    bad_input = (SceneError, DecompositionError, UsageError, ck.CheckpointError,
                 rundir.RunDirError)
    lock = None
    try:
        if args.stop_after is not None and args.stop_after < 1:
            raise UsageError(f"--stop-after must be a step >= 1 (got {args.stop_after})")
        if args.restart:
            if args.scene:
                raise UsageError("give either SCENE or --restart (the scene is in the checkpoint)")
            if args.overwrite:
                raise UsageError("--overwrite replaces a run; a restart continues one")
            info = ck.read_scene(args.restart)
            text = info.scene
            overrides = info.overrides + list(args.set)
            scene = sc.parse(text, str(args.restart), overrides)
            check_same_physics(sc.parse(text, str(args.restart), info.overrides), scene)
            out = Path(args.out) if args.out else Path(args.restart).resolve().parent
        else:
            if not args.scene:
                raise UsageError("run needs a SCENE (or --restart CHECKPOINT)")
            source, overrides = sc.expand_case(args.scene, args.set)
            scene, text = sc.load(source, overrides)
            out = Path(args.out) if args.out else Path("runs") / scene.name
        h5 = out / rundir.RUN_FILE
        n_steps = scene.time.n_steps
        if args.stop_after is not None and args.stop_after >= n_steps:
            raise UsageError(f"--stop-after {args.stop_after} is not before the run's last step "
                             f"{n_steps}: the run would end without stopping there (and with "
                             "no checkpoint unless output.checkpoint_every > 0)")
        if args.restart and args.stop_after is not None and args.stop_after <= info.step:
            raise UsageError(f"--stop-after {args.stop_after} is not after the checkpoint's "
                             f"step {info.step}")
        if args.restart:
            if n_steps < info.step:
                raise UsageError(f"the run length ({n_steps} steps) ends before the "
                                 f"checkpoint's step {info.step}")

            def restart_checks():
                return rundir.check_restart(out, info.run_id, text, info.n_points,
                                            scene.output.every, scene.time.dt, info.step,
                                            n_steps)
            if _on_root(team, restart_checks):
                if team.root:
                    print(f"mpipd: {h5} is complete to step {n_steps} of {n_steps}: nothing "
                          "to do (nothing written; set a longer time.t_end or time.steps to "
                          "extend it)", flush=True)
                return 0
        else:
            def new_run_checks():
                rundir.check_new_run(out, args.overwrite)
            _on_root(team, new_run_checks)
        check_parts(scene.parts)             # geometry first: empty, oversized, overlapping
        check_charges(scene)                 # a charge lit from outside it, or after t_end
        dt_stable = critical_dt(scene)
        if scene.time.dt > dt_stable and not args.force:
            raise UsageError(f"time.dt = {scene.time.dt:.4e} s exceeds the stable estimate "
                             f"{dt_stable:.4e} s (see `mpipd check`); use --force to run anyway")
        hosts = team.gather((socket.gethostname(), _mem_available()))
        _on_root(team, _check_sizes, scene, team.size, hosts, out, args)
        sim = Simulation(scene, team)
        restored = ck.restore(sim, args.restart) if args.restart else None
        # the first write of the run: the folder's lock, then the checks again under it
        # (another run may have started or finished since)
        lock = rundir.RunLock(out) if team.root else None
        _on_root(team, lock.acquire if team.root else None)
        if args.restart:
            _on_root(team, restart_checks)
        else:
            _on_root(team, new_run_checks)
        _on_root(team, rundir.ensure_writable, out)
    except bad_input as e:
        if lock is not None:
            lock.release(remove_dir=True)
        return _bad_input(team, e)
    except BaseException:
        if lock is not None:
            lock.release()
        raise
    try:
        if args.restart:
            run_id, resume, shown = info.run_id, True, _shown(text, overrides)
        else:
            run_id, resume, shown = team.bcast(rundir.new_run_id() if team.root else None), \
                False, _shown(text, overrides)
            if args.overwrite and team.root:
                rundir.clear_old_run(out)
        team.barrier()
        try:
            return RunIO(args=args, team=team, signals=signals, scene=scene, sim=sim,
                         text=text, overrides=overrides, shown=shown, out=out, h5=h5,
                         n_steps=n_steps, dt_stable=dt_stable, run_id=run_id, resume=resume,
                         restored=restored).execute()
        except Exception as e:
            line = rundir.io_line(e, out)
            if line is None:
                raise
            for tmp in out.glob("*.h5.tmp"):         # a checkpoint that did not finish
                try:
                    tmp.unlink()
                except OSError:
                    pass
            raise IOFailure(line) from None
    finally:
        if lock is not None:
            lock.release()


def _mem_available():
    from .check import mem_available
    return mem_available()


def _free_bytes(out: Path) -> int:
    """Free bytes (for this user) on the file system that holds ``out`` or, if it
    does not exist yet, its nearest existing parent."""
    p = out.resolve()
    while not p.exists():
        p = p.parent
    st = os.statvfs(p)
    return st.f_bavail * st.f_frsize


#: the share of the free space a new run file may take (the rest is left to the
#: checkpoints, the log and whatever else shares the file system)
FREE_SHARE = 0.9


def _check_sizes(scene, ranks, hosts, out: Path, args):
    """Refuse (UsageError: one line with the numbers and --force-size) a run whose
    run file, as allocated before step 1, exceeds the free space where it goes, or
    whose model (mpipd.check's memory model) exceeds the memory available on a host
    of the job -- before anything is built or written.  A restart needs only what
    its run file grows by; --overwrite counts the old run's files as free."""
    from .check import gb, sizes
    from .output import rundir
    from .output.writer import n_frames
    sz = sizes(scene, ranks)
    h5 = out / rundir.RUN_FILE
    need, free = sz.run_file, _free_bytes(out)
    if args.restart and h5.exists():
        need = max(0, need - h5.stat().st_size)
    elif args.overwrite and out.is_dir():
        free += sum((out / n).stat().st_size for n in (rundir.RUN_FILE, "run.xdmf",
                                                       *rundir.OLD_RUN_FILES)
                    if (out / n).is_file())
    frames = n_frames(scene.time.n_steps, scene.output.every)
    if need > FREE_SHARE * free and not args.force_size:
        raise UsageError(f"the run file {h5} needs about {gb(need)} ({frames} frame(s) of "
                         f"{len(scene.output.fields)} field(s) x {sz.points} points"
                         + (f", {len(scene.probes)} probe(s) x {scene.time.n_steps + 1} steps"
                            if scene.probes else "") + "), allocated before step 1; "
                         f"{gb(free)} free there, and a run may take at most "
                         f"{FREE_SHARE:.0%} of it (time.t_end, time.steps or output.every "
                         "mistyped?); --force-size to run anyway")
    per_host: dict = {}
    for r, (host, avail) in enumerate(hosts):
        used, have = per_host.get(host, (0, avail))
        per_host[host] = (used + sz.memory[r], have)
    for host, (used, have) in per_host.items():
        if have is not None and used > have and not args.force_size:
            raise UsageError(f"the model needs about {gb(used)} on host {host} "
                             f"({gb(max(sz.memory))} on its largest rank of {ranks}, "
                             f"{sz.points} points, {sz.bonds} bonds; `mpipd check`), "
                             f"{gb(have)} available there: use more nodes or a coarser dx; "
                             "--force-size to run anyway")


def _shown(text: str, overrides) -> str:
    """The scene text as a run file stores it: the TOML and its --set overrides."""
    from .output.rundir import OVERRIDES_MARK
    return text + (OVERRIDES_MARK + "".join(f"# {o}\n" for o in overrides) if overrides else "")


def _on_root(team, fn, *args):
    """Run a serial check on rank 0; its error is raised on every rank, else its
    value returned on every rank."""
    err = value = None
    if team.root:
        try:
            value = fn(*args)
        except Exception as e:               # re-raised on every rank below
            err = e
    err, value = team.bcast((err, value))
    if err is not None:
        raise err
    return value


def _end_checkpoint(checkpointer, team, out) -> str | None:
    """Write a finished run's last checkpoint (collective).  The run file is already
    closed and whole, so a file system that refuses the checkpoint (disk full,
    read-only) does not end the run here: the reason comes back as one line for the
    end of the summary (exit 4); None if written.  The ranks agree on it."""
    from .output import rundir
    err = None
    try:
        checkpointer.at_end()
    except Exception as e:
        err = rundir.io_line(e, out)
        if err is None:
            raise
    return next((e for e in team.gather(err) if e), None)


@dataclass
class RunIO:
    """One invocation of ``mpipd run`` past its checks: the command's ``args``, ``team``
    and ``signals``; the ``scene``, its built Simulation ``sim``, the scene ``text``
    and its --set ``overrides`` (``shown``: both as the run file stores them); the run
    folder ``out`` and its run file ``h5``; the run length ``n_steps``, the stable
    estimate ``dt_stable`` dt was checked against (mpipd.model.stability.critical_dt),
    the run's id, whether it continues a run file (``resume``) and the restored
    checkpoint's warning (``restored``).  ``log`` writes the run log (rank 0)."""
    args: argparse.Namespace
    team: Any
    signals: Any
    scene: Any
    sim: Any
    text: str
    overrides: list
    shown: str
    out: Path
    h5: Path
    n_steps: int
    dt_stable: float
    run_id: str
    resume: bool
    restored: str | None = None
    log: RunLog = field(init=False)

    def __post_init__(self):
        self.log = RunLog(self.out / "run.log", self.team)

    def header(self):
        """The run log's first lines: what runs, and the warnings of its set-up
        (collective: the counts are summed over the ranks)."""
        log, team, scene, sim = self.log, self.team, self.scene, self.sim
        what = f"restart at step {sim.step_count}, " if self.args.restart else ""
        log(f"mpipd: {scene.name}: {what}{sim.n_global} points, {sim.n_bonds_global} bonds, "
            f"{team.size} rank(s), {self.n_steps} steps of {scene.time.dt:.3e} s -> {self.h5}")
        if self.restored:                     # the checkpoint's own warning (no checksums)
            log(f"mpipd: warning: {self.restored}")
        if scene.time.dt > self.dt_stable:
            log(f"mpipd: warning: dt = {scene.time.dt:.4e} s exceeds the stable estimate "
                f"{self.dt_stable:.4e} s (--force); the run may blow up")
        n_spring = sim.spring_points()        # after the restore, on a restart
        if n_spring:
            n_soft = team.sum(sim.corr.count_floor())
            log(f"mpipd: {n_spring} point(s) use the bond-spring fallback "
                "(shape tensor not invertible" + (f", or, {n_soft} of them, invertible but too "
                                                  "soft for dt (on a restart: switched before "
                                                  "the checkpoint); mpipd.model.correspondence."
                                                  "stable_floor"
                                                  if n_soft else "") + ")")
        for note in (sim.probes.notes if sim.probes is not None else ()):
            log(f"mpipd: warning: {note}")
        if sim.interface is not None:
            full, planar, left = (team.sum(c) for c in sim.interface.counts)
            log(f"mpipd: interface correction: {full} point(s) in full, {planar} in the x-y "
                f"plane (near a z face); {left} keep their ghost force (an interface within "
                "two horizons of an x-y free surface, or of a part that is no prism along z, "
                "README)")
        if sim.joint_bonds:
            log(f"mpipd: joints: {sim.joint_bonds} bond(s) start broken (counted from both ends)")

    def over_dt(self, failed: bool = False) -> str | None:
        """The multi-rate line on points whose stable step fell below dt in this
        invocation (collective; None if none did, or single-rate; ``failed``: split at
        the last frame, StepClasses.over_line)."""
        sim = self.sim
        return (sim.classes.over_line(self.team, list(self.scene.materials), failed)
                if sim.classes.enabled else None)

    def segment(self, first: int, wall: float) -> dict:
        """This invocation's record (collective).  Every rank must write the same
        attribute: the loop's wall time is the slowest rank's (each rank's own
        differed, and ranks writing different strings corrupted ``segments``)."""
        sim, team = self.sim, self.team
        done = sim.step_count - first
        w = team.max(wall)
        return {"from_step": first, "to_step": sim.step_count, "ranks": team.size,
                "wall_s": round(w, 3),
                "bond_steps_per_s": sim.n_bonds_global * done / w if w > 0 else None,
                "bond_states_evaluated": round(sim.classes.evaluated_share(team), 4),
                **({"restart_set": list(self.args.set)} if self.args.restart else {})}

    def execute(self) -> int:
        """Run the time loop with the run file, progress lines and checkpoints; the
        exit status (0, or EXIT_UNSTABLE, or EXIT_IO for a finished run whose end
        checkpoint failed) after the log's last lines (:func:`summary`)."""
        from .output import checkpoint as ck
        from .output.writer import Writer
        from .solver import Progress, Unstable
        args, team, scene, sim, log, n_steps = (self.args, self.team, self.scene, self.sim,
                                                self.log, self.n_steps)
        self.header()
        writer = Writer(self.h5, sim, self.shown, n_steps, resume=self.resume,
                        run_id=self.run_id)
        progress = None if args.quiet else Progress(team, scene.solver.progress_every, log=log)
        checkpointer = ck.Checkpointer(sim, self.out / "checkpoint.h5", self.text,
                                       self.overrides, every=scene.output.checkpoint_every,
                                       stop_after=args.stop_after, run_id=self.run_id)
        checkpointer.install_signals(self.signals)
        first = sim.step_count
        wall = 0.0
        try:
            wall = sim.run(n_steps, writer=writer, every=scene.output.every, progress=progress,
                           checkpointer=checkpointer)
        except Unstable as e:
            writer.close()
            over = self.over_dt(failed=True)
            log(f"mpipd: error: {e}; state saved in {checkpointer.written}"
                + (f"; {over}" if over else ""), error=True)
            return EXIT_UNSTABLE
        writer.close(self.segment(first, wall))
        end_error = (_end_checkpoint(checkpointer, team, self.out) if sim.step_count == n_steps
                     else None)
        if sim.step_count < n_steps:
            # what this invocation saw of the stable step: the next one counts afresh
            n_switched = team.sum(sim.corr.floor_switches)
            over = self.over_dt()
            log(f"mpipd: stopped at step {sim.step_count} of {n_steps}; {n_switched} "
                "stable-step switch(es) from the correspondence force in this invocation "
                f"(mpipd.model.correspondence.stable_floor); checkpoint {checkpointer.written}; "
                f"continue with `mpipd run --restart {shlex.quote(str(checkpointer.written))}`")
            if over:
                log(f"mpipd: warning: {over}", error=True)
            return 0
        return summary(self, first, wall, checkpointer, end_error)


def summary(run: RunIO, first: int, wall: float, checkpointer, end_error: str | None) -> int:
    """The run log's last lines of a finished run (collective: sums over the ranks):
    speed, fallback and failed points, step classes, the energy ledger, the gas and
    the probes, the files written; EXIT_IO (after its line) if the end checkpoint
    ``end_error`` was not written, else 0.  ``first``: the invocation's first step;
    ``wall``: its loop's wall time (s)."""
    from .model.ledger import impossible
    log, team, sim, n_steps, h5 = run.log, run.team, run.sim, run.n_steps, run.h5
    n_spring = sim.spring_points()
    n_floor = team.sum(sim.corr.count_floor())
    n_switched = team.sum(sim.corr.floor_switches)
    failed = sim.failure_counts()
    broken = sim.bonds_broken()
    rate = sim.n_bonds_global * (n_steps - first) / max(wall, 1e-12)    # this invocation's
    log(f"mpipd: done in {wall:.2f} s" + (f" (steps {first}-{n_steps})" if first else "")
        + f": {rate / 1e6:.2f} M bond-steps/s, "
        f"{rate / team.size / 1e6:.2f} M per rank; spring-fallback points: {n_spring}"
        + (f" ({n_floor} of them with an invertible shape tensor too soft for dt; "
           f"{n_switched} such switch(es) from the correspondence force in this "
           "invocation, mpipd.model.correspondence.stable_floor)"
           if n_floor or n_switched else ""))
    if sim.failure is not None:
        log("mpipd: failed points: " + ", ".join(f"{failed[k]} {MODE_NAMES[k]}"
                                                 for k in range(1, N_MODES))
            + f"; {broken} bonds broken")
    if sim.classes.enabled:
        log("mpipd: " + sim.classes.summary(team))
        over = run.over_dt()
        if over:
            log(f"mpipd: warning: {over}", error=True)
    e = sim.energies()
    log(f"mpipd: energy ledger: initial {e.initial:.6g} J + external {e.external:.6g} J"
        + (f" + boundary {e.boundary:.6g} J" if e.boundary else "") + " = "
        f"held {e.held:.6g} J + dissipated {e.dissipated:.6g} J; balance {e.balance:+.2e}")
    for msg in impossible(e):
        log(f"mpipd: warning: impossible energy: {msg}", error=True)
    if sim.gas is not None:
        _gas_summary(log, team, sim.gas)
    if sim.probes is not None:
        for name, (srr, vr, pmax) in sim.probes.peaks().items():
            log(f"mpipd: probe {name}: peak radial stress {srr / 1e6:.1f} MPa, peak |v_r| "
                f"{vr:.2f} m/s, peak pressure {pmax / 1e6:.1f} MPa")
    log(f"mpipd: wrote {h5} and {h5.with_suffix('.xdmf')}")
    _warnings(log, team, h5, sim)
    if end_error:
        kept = (f"{checkpointer.path.name} is still step {checkpointer.written_step}'s"
                if checkpointer.written_step is not None
                else f"{checkpointer.path.name} is an earlier invocation's"
                if checkpointer.path.exists() else "no checkpoint")
        log(f"mpipd: error: {end_error}: the end checkpoint was not written ({kept}); "
            f"the run file {h5} is complete to step {n_steps}", error=True)
        return EXIT_IO
    return 0


def _warnings(log, team, h5, sim):
    """The block of warnings a user cannot miss (mpipd.post.alerts), read back from the
    finished run file (collective); a failure to read it is one line, never the run's."""
    try:
        from .post import alerts
        from .post.model import load_model
        from .post.reader import Run
        end = None
        if sim.gas is not None:
            end = (team.sum(int(sim.gas.n_singular)), team.sum(len(sim.gas.gas_idx)))
        run = Run(h5, team.comm)
        try:
            found = alerts.collect(run, load_model(run), end_no_force=end)
        finally:
            run.close()
    except Exception as e:                                  # noqa: BLE001
        log(f"mpipd: warning: the run's warnings could not be checked ({e})", error=True)
        return
    for line in alerts.lines(found):
        log(f"mpipd: {line}", error=True)


def _gas_summary(log, team, gas):
    """The explosive's lines of the summary (collective): its peak pressure beside the
    material's Chapman-Jouguet state and the paper's reported peak
    (mpipd.materials.jwl.PAPER_PEAK_PRESSURE), the density at lighting, the points
    carrying no force and the family searches."""
    from .materials.jwl import PAPER_PEAK_PRESSURE
    peak = team.max(gas.peak_pressure)
    m = gas.mat
    cj = m.chapman_jouguet()
    log(f"mpipd: peak gas pressure {peak / 1e9:.3f} GPa (pressure_factor {m.pressure_factor:g}; "
        f"Table 2 implies p_CJ = {cj['p'] / 1e9:.2f} GPa, D_CJ = {cj['D']:.0f} m/s; "
        f"the paper reports up to {PAPER_PEAK_PRESSURE / 1e9:.1f} GPa)")
    lit = gas.lit_density(team)
    log("mpipd: density at lighting (x the charge's): " + "; ".join(
        f"{k} max {v['max']:.3f}, mean {v['mean']:.3f}"
        + (f", {v['lit_fraction']:.0%} lit" if v["lit_fraction"] < 1 else "")
        for k, v in lit.items()))
    off, n_gas = (team.sum(int(gas.n_singular)), team.sum(len(gas.gas_idx)))
    log(f"mpipd: gas points carrying no force at the end (no gas neighbourhood, "
        f"mpipd.kernels.ul.well_posed, or a family collapsing in a step, "
        f"MAX_VOLUME_STRAIN): {off} of {n_gas}")
    log(f"mpipd: gas families searched {team.max(gas.searches)} times in this "
        f"invocation, {team.max(gas.search_seconds):.1f} s on the slowest rank "
        f"(mpipd.model.gas: Verlet skin tuned on the cost, {gas.skin * 1e3:.3g} mm at the last search)")


class RunLog:
    """Rank 0 prints each line and appends it to the run's log file."""

    def __init__(self, path, team):
        self.path = path
        self.root = team.root

    def __call__(self, msg: str, error: bool = False):
        if not self.root:
            return
        print(msg, file=sys.stderr if error else sys.stdout, flush=True)
        with open(self.path, "a") as f:
            f.write(msg + "\n")


if __name__ == "__main__":
    sys.exit(main())
