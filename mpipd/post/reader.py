"""Open a run file collectively and give each rank its slice of global ids.

Every rank of ``comm`` opens the file with h5py's ``mpio`` driver and reads only
its own contiguous gid range ``lo:hi`` of any per-point dataset.  Global ids run
over z levels (``mpipd.input.geometry``: gids follow (z, material, part, y, x)), and the
reading slices are cut on **whole z levels**: a cross-section is then never
split between ranks, and a sum is formed per z level on the rank that owns the
level and the per-level partial sums are added in global level order
(:meth:`Run.level_total`).  So every number is bit-identical whatever the number
of reading ranks.

Without a communicator (``comm=None``) one process reads the whole file, with HDF5's
default driver and no MPI at all (:class:`SerialComm` stands in for the communicator):
the same code, one rank.

A file that is not an mpipd run file (foreign or truncated HDF5, no frames)
raises :class:`RunFileError` with a one-line message, on every rank alike.
"""
from __future__ import annotations

import numpy as np

from mpipd.parallel.team import Team

REQUIRED = ("geometry/x", "geometry/volume", "geometry/part", "geometry/material", "time")


def shown_path(path) -> str:
    """A run file as reports and the record name it: relative to the working directory
    when it lies under it (so that no machine path lands in a committed report), else
    absolute."""
    from pathlib import Path
    p = Path(path).resolve()
    try:
        return str(p.relative_to(Path.cwd().resolve()))
    except ValueError:
        return str(p)


class SerialComm:
    """The communicator of a single process without MPI: the few mpi4py calls the
    reader and the analyses make, each what it is on one rank (a reduction or a gather
    of one value is that value).  Used when a run file is opened without ``comm``."""

    def Get_rank(self) -> int:
        return 0

    def Get_size(self) -> int:
        return 1

    def allgather(self, x) -> list:
        return [x]

    def gather(self, x, root=0) -> list:
        return [x]

    def bcast(self, x, root=0):
        return x

    def allreduce(self, x, op=None):
        return x

    def Allreduce(self, sendbuf, recvbuf, op=None):
        recvbuf[...] = sendbuf

    def Barrier(self):
        pass

    def Abort(self, code=1):
        raise SystemExit(code)


class _SerialTeam(Team):
    """:class:`~mpipd.parallel.team.Team` on a :class:`SerialComm`: its reductions need
    no MPI operation (and so never import mpi4py)."""

    def _op(self, name):
        return name


class RunFileError(Exception):
    """The file cannot be analysed (one line, names the file and the reason)."""


def _one_line(e) -> str:
    return " ".join(str(e).split())


class Run:
    """A run file opened by every rank of ``comm`` (or, with ``comm=None``, by this
    process alone, without MPI); ``lo:hi`` is this rank's gid slice (whole z levels);
    ``levels`` are the local offsets where a z level starts."""

    def __init__(self, path, comm=None):
        import h5py
        self.path = str(path)
        self._geo = {}
        if comm is None:
            self.comm = SerialComm()
            self.team = _SerialTeam(self.comm)
            mode = {}
        else:
            self.comm = comm
            self.team = Team(comm)
            mode = {"driver": "mpio", "comm": comm}
        try:
            self.f = h5py.File(path, "r", **mode)
        except (OSError, ValueError) as e:
            raise RunFileError(f"cannot open {path}: {_one_line(e)}") from None
        try:
            self._validate()
            self._partition()
        except RunFileError:
            self.f.close()
            raise
        except (OSError, KeyError, ValueError, TypeError) as e:
            self.f.close()
            raise RunFileError(f"{path}: unreadable run file ({_one_line(e)})") from None

    # ------------------------------------------------------------------ checks
    def _validate(self):
        f, path = self.f, self.path
        for key in ("n_points", "frames_written"):
            if key not in f.attrs:
                raise RunFileError(f"{path}: not an mpipd run file (no attribute {key!r})")
        for key in REQUIRED:
            if key not in f:
                raise RunFileError(f"{path}: not an mpipd run file (no dataset /{key})")
        self.n_points = int(f.attrs["n_points"])
        self.frames = int(f.attrs["frames_written"])
        if self.n_points <= 0 or f["geometry/x"].shape != (self.n_points, 3):
            raise RunFileError(f"{path}: /geometry/x does not hold n_points = {self.n_points} "
                               "positions")
        if self.frames <= 0:
            raise RunFileError(f"{path}: no frames written (the run stopped before its "
                               "first output)")
        if f["time"].shape[0] < self.frames:
            raise RunFileError(f"{path}: /time holds {f['time'].shape[0]} values but "
                               f"frames_written = {self.frames} (truncated file)")
        for name in self.f.get("fields", {}):
            d = f["fields"][name]
            if d.shape[0] < self.frames or d.shape[1] != self.n_points:
                raise RunFileError(f"{path}: /fields/{name} has shape {d.shape}, expected "
                                   f"({self.frames}+, {self.n_points}, ...)")

    def _partition(self):
        """Cut the naive slices ``N r / n`` forward to the next start of a z level."""
        r, n, N = self.comm.Get_rank(), self.comm.Get_size(), self.n_points
        lo0, hi0 = N * r // n, N * (r + 1) // n
        a = max(lo0 - 1, 0)
        z = self._z_level(a, hi0)
        starts = np.flatnonzero(np.diff(z) != 0) + 1 + a     # gids where a new level begins
        first = int(starts[starts >= lo0][0]) if np.any(starts >= lo0) else N
        if lo0 == 0:
            first = 0
        firsts = self.comm.allgather(first)
        self.lo = min(firsts[r:]) if r else 0
        self.hi = min(firsts[r + 1:] + [N])
        self.hi = max(self.hi, self.lo)
        zl = self._z_level(self.lo, self.hi)
        self.levels = (np.concatenate(([0], np.flatnonzero(np.diff(zl) != 0) + 1))
                       if len(zl) else np.zeros(0, dtype=np.int64))
        self.level_z = zl[self.levels] if len(zl) else np.zeros(0)
        self.n_levels = self.sum_int(len(self.levels))

    def _z_level(self, a: int, b: int) -> np.ndarray:
        """The z of the lattice level of points a:b: ``/geometry/z_level`` where the
        lattice is jittered (mpipd.input.geometry), else the points' own z."""
        g = self.f["geometry"]
        return g["z_level"][a:b] if "z_level" in g else g["x"][a:b, 2]

    @property
    def z_level(self) -> np.ndarray:
        """This rank's points' lattice level z (their z on an unjittered lattice):
        a section at a level is the points whose z_level equals it."""
        if "z_level" not in self._geo:
            self._geo["z_level"] = self._z_level(self.lo, self.hi)
        return self._geo["z_level"]

    # ------------------------------------------------------------------ reads
    def geometry(self, name: str) -> np.ndarray:
        """This rank's slice of ``/geometry/name`` (read once, then cached)."""
        if name not in self._geo:
            self._geo[name] = self.f["geometry"][name][self.lo:self.hi]
        return self._geo[name]

    def names(self, key: str) -> list[str]:
        """The names of the materials (``key="material"``) or parts (``"part"``), indexed
        by the ids in ``/geometry/<key>`` (its ``names`` attribute)."""
        names = self.f["geometry"][key].attrs.get("names", [])
        return [n.decode() if isinstance(n, bytes) else str(n) for n in names]

    def has_field(self, name: str) -> bool:
        return "fields" in self.f and name in self.f["fields"]

    @property
    def field_names(self) -> list[str]:
        return list(self.f["fields"]) if "fields" in self.f else []

    def field(self, name: str, frame=slice(None), span=None) -> np.ndarray:
        """``/fields/name[frame, lo:hi]`` (or ``[frame, lo + a : lo + b]`` for span (a, b)).
        ``frame`` counts the written frames only (``frames_written``; a run that
        stopped early, or is still running, has frames allocated but not yet written,
        NaN): a slice is cut to them, a negative index counts from the last written."""
        if not self.has_field(name):
            raise KeyError(f"the run has no field {name!r} "
                           f"(it has: {', '.join(self.field_names) or 'none'})")
        frame = self.written(frame)
        a, b = (0, self.hi - self.lo) if span is None else span
        return self.f["fields"][name][frame, self.lo + a:self.lo + b]

    def written(self, frame):
        """``frame`` (an index or a slice) within the written frames: a slice cut to
        them, an index as a non-negative one (negative counts from the last written);
        an index outside them raises IndexError."""
        if isinstance(frame, slice):
            r = range(self.frames)[frame]
            return slice(r.start, r.stop if r.stop >= 0 else None, r.step)
        if isinstance(frame, (int, np.integer)):
            if not -self.frames <= frame < self.frames:
                raise IndexError(f"frame {int(frame)}: {self.path} holds {self.frames} "
                                 "written frame(s)")
            return int(frame) % self.frames
        return frame

    @property
    def time(self) -> np.ndarray:
        return self.f["time"][: self.frames]

    def energy(self, name: str) -> np.ndarray:
        return self.f["energy"][name][: self.frames]

    def has_energy(self, name: str) -> bool:
        return "energy" in self.f and name in self.f["energy"]

    def attr(self, key, default=None):
        v = self.f.attrs.get(key, default)
        return v.decode() if isinstance(v, bytes) else v

    # ------------------------------------------------------------- reductions
    def per_level(self, values: np.ndarray) -> np.ndarray:
        """Sums of ``values`` (local points first, any trailing shape) over each local
        z level; rows = local levels."""
        if len(self.levels) == 0:
            return np.zeros((0,) + values.shape[1:])
        return np.add.reduceat(values, self.levels, axis=0)

    def per_level_bins(self, bins: np.ndarray, mask: np.ndarray, nb: int,
                       weights: np.ndarray | None = None) -> np.ndarray:
        """(local levels, nb) sums of ``weights`` (or counts) of the masked points by
        (z level, bin); points are added in gid order, so a level's row does not
        depend on the reading ranks."""
        n = self.hi - self.lo
        lev = np.zeros(n, dtype=np.int64)
        if len(self.levels) > 1:
            lev[self.levels[1:]] = 1
            lev = np.cumsum(lev)
        key = lev[mask] * nb + bins[mask]
        w = None if weights is None else weights[mask]
        return np.bincount(key, weights=w, minlength=len(self.levels) * nb
                           ).astype(float).reshape(len(self.levels), nb)

    def all_levels(self, local: np.ndarray) -> np.ndarray:
        """Per-level rows of every rank, in global level order (every rank gets them)."""
        parts = self.comm.allgather(np.asarray(local))
        return np.concatenate(parts, axis=0)

    def level_total(self, local: np.ndarray) -> np.ndarray:
        """Sum over all z levels of per-level rows, in global level order: the same
        floating-point result on any number of ranks."""
        return self.all_levels(local).sum(axis=0)

    # Reductions over the reading ranks: mpipd.parallel.team.Team's (one implementation
    # for the solver and the postprocessor); a number, or a NumPy array elementwise.
    def max(self, x):
        return self.team.max(x)

    def min(self, x):
        return self.team.min(x)

    def sum_int(self, x):
        """Sum over ranks of an integer (exact in any order)."""
        return self.team.sum(x)

    def max_array(self, x: np.ndarray) -> np.ndarray:
        return self.team.max(np.asarray(x))

    def sum_array(self, x: np.ndarray) -> np.ndarray:
        """Elementwise sum over ranks of an integer array (exact in any order)."""
        return self.team.sum(np.asarray(x))

    @property
    def root(self) -> bool:
        return self.comm.Get_rank() == 0

    def close(self):
        self.f.close()
