"""The Python API for notebooks: :func:`open` a run file and read it as NumPy arrays.

    import mpipd
    run = mpipd.open("runs/demo/run.h5")
    run.frames, run.times                  # written frames and their times (s)
    run.materials, run.parts               # names, indexed by the ids in the file
    phi = run.field("damage", frame=-1)    # one value a point, in gid order
    sec = run.section(z=0.0005, part="rock")
    run.probes["A"]["sigma_rr"]            # a probe's record, one row a step
    run.energy["balance"]                  # the energy ledger, one row a frame

**Serial by default.**  Without ``comm`` one process reads the file with HDF5's
default driver and no MPI (:class:`mpipd.post.reader.SerialComm` stands in for the
communicator), so a notebook needs neither ``mpirun`` nor mpi4py's initialisation.
Given ``comm=`` (an mpi4py communicator), every rank of it opens the file collectively
(the ``mpio`` driver) and reads its own slice of whole z levels
(:mod:`mpipd.post.reader`): per-point arrays (:meth:`RunFile.field`,
:attr:`RunFile.x`, ...) are then the rank's slice (``gid_range``), a section is
gathered to rank 0 (None elsewhere), and the small things (times, names, probes, the
ledger) are read whole by every rank.

The section is :func:`mpipd.post.sections.section`, the one that
``python -m mpipd.post fracture`` draws.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from mpipd.model.ledger import TERMS

from .reader import Run
from .sections import Section, part_mask, section

__all__ = ["open", "RunFile", "Probe", "Section"]


@dataclass(frozen=True)
class Probe:
    """One probe of a run: the point it records and its record.

    ``name``; ``gid`` and ``x`` (m): the lattice point it records (the one nearest the
    requested ``position``, m, among the points of its part); ``part`` and
    ``material``: that point's part (the zone holding it) and material names;
    ``data``: quantity -> array, one row a step, the rows never written (a run that
    stopped early) left out.  The quantities are those of
    :data:`mpipd.output.probes.QUANTITIES` the file holds: ``t`` (s), ``sigma_rr``
    (Pa, radial stress, tension positive), ``v_r`` (m/s), ``p`` (Pa, pressure,
    compression positive), ``s`` (Pa, von Mises), ``strength`` (Pa, JH2 yield
    strength, NaN for other materials), ``t_state`` (s).  ``probe["sigma_rr"]`` is
    ``probe.data["sigma_rr"]``."""
    name: str
    gid: int
    x: np.ndarray
    position: np.ndarray | None
    part: str
    material: str
    data: dict = field(repr=False)

    def __getitem__(self, quantity: str) -> np.ndarray:
        return self.data[quantity]

    def keys(self):
        """The quantities recorded (``t``, ``sigma_rr``, ...)."""
        return self.data.keys()


def _text(v):
    """An HDF5 attribute as Python: bytes as str, NumPy scalars as Python numbers."""
    if isinstance(v, bytes):
        return v.decode()
    if isinstance(v, np.generic):
        return v.item()
    return v


class RunFile:
    """A run file (``run.h5``) opened for reading: serially (``comm=None``) or by every
    rank of ``comm``.  Made by :func:`open`; a context manager (``with mpipd.open(p) as
    run:``) that closes the file at the end, or call :meth:`close`."""

    def __init__(self, path, comm=None):
        self._run = Run(path, comm)
        self.path = self._run.path
        self._probes = None

    # ------------------------------------------------------------ what the file holds
    @property
    def n_points(self) -> int:
        """The number of points of the model (every rank's)."""
        return self._run.n_points

    @property
    def frames(self) -> int:
        """The number of frames written (a run still going or stopped early has more
        allocated, not yet written, and never read)."""
        return self._run.frames

    @property
    def times(self) -> np.ndarray:
        """The time of each written frame (s), shape ``(frames,)``."""
        return self._run.time

    @property
    def materials(self) -> list[str]:
        """The material names; material id ``i`` in the file is ``materials[i]``."""
        return self._run.names("material")

    @property
    def parts(self) -> list[str]:
        """The part names (a part split into zones has one name a zone,
        ``rock.ring1`` ...); part index ``i`` in the file is ``parts[i]``."""
        return self._run.names("part")

    @property
    def fields(self) -> list[str]:
        """The names of the fields written at every frame (``damage``, ``u``, ...)."""
        return self._run.field_names

    @property
    def attrs(self) -> dict:
        """The run file's attributes (``scene`` text, ``scene_name``, ``git_commit``,
        ``dt``, ``steps``, ``ranks``, ...), strings decoded."""
        return {k: _text(v) for k, v in self._run.f.attrs.items()}

    @property
    def gid_range(self) -> tuple[int, int]:
        """The global ids ``lo:hi`` this process reads (``0:n_points`` serially)."""
        return self._run.lo, self._run.hi

    # ------------------------------------------------------------ per-point arrays
    def _mask(self, part):
        return None if part is None else part_mask(self._run, part)

    def _points(self, values, part):
        m = self._mask(part)
        return values if m is None else values[m]

    @property
    def x(self) -> np.ndarray:
        """The points' reference positions (m), shape ``(n, 3)``, in gid order."""
        return self._run.geometry("x")

    @property
    def volume(self) -> np.ndarray:
        """The points' volumes (m³), in gid order."""
        return self._run.geometry("volume")

    @property
    def part_ids(self) -> np.ndarray:
        """Each point's part index (into :attr:`parts`), in gid order."""
        return self._run.geometry("part")

    @property
    def material_ids(self) -> np.ndarray:
        """Each point's material id (into :attr:`materials`), in gid order."""
        return self._run.geometry("material")

    def mask(self, part: str) -> np.ndarray:
        """True for the points of ``part`` (the part of that name and its zones)."""
        return part_mask(self._run, part)

    def positions(self, part: str | None = None) -> np.ndarray:
        """Reference positions (m) of the points, or of ``part``'s points only."""
        return self._points(self.x, part)

    def field(self, name: str, frame: int | slice = -1, part: str | None = None) -> np.ndarray:
        """``/fields/name`` at ``frame`` (an index among the written frames, negative from
        the last; or a slice of them, giving a leading frame axis): one row a point, in
        gid order (``(n,)`` for a scalar, ``(n, k)`` for a vector or tensor); with
        ``part``, that part's points only.  An unknown field raises KeyError naming the
        fields; a frame outside the written ones, IndexError."""
        values = self._run.field(name, self._run.written(frame))
        m = self._mask(part)
        if m is None:
            return values
        return values[:, m] if isinstance(frame, slice) else values[m]

    def section(self, z: float | None = None, part: str | None = None,
                field: str = "damage", frame: int = -1) -> Section | None:
        """The points of the z level nearest ``z`` (m; default: the middle of the body,
        or of ``part``) and ``field`` at ``frame`` on them: a
        :class:`~mpipd.post.sections.Section` (``x``, ``y``, ``gid``, ``values``, ``z``,
        ``time``).  With ``part``, the nearest level that holds that part's points, and
        its points only.  Under MPI: collective, the section on rank 0 and None on the
        other ranks."""
        return section(self._run, field, frame, z, part)

    # ------------------------------------------------------------ small tables
    @property
    def probes(self) -> dict[str, Probe]:
        """Probe name -> :class:`Probe` (read once; an empty dict if the scene has none)."""
        if self._probes is None:
            import h5py
            f = self._run.f
            parts, mats = self.parts, self.materials
            out = {}
            for name, g in (f["probes"].items() if "probes" in f else ()):
                data = {q: g[q][...] for q in g if isinstance(g[q], h5py.Dataset)}
                keep = np.isfinite(data["t"]) if "t" in data else slice(None)
                gid = int(g.attrs["gid"])
                pos = g.attrs.get("position")
                out[name] = Probe(
                    name=name, gid=gid, x=np.asarray(f["geometry/x"][gid]),
                    position=None if pos is None else np.asarray(pos, float),
                    part=parts[int(f["geometry/part"][gid])],
                    material=mats[int(f["geometry/material"][gid])],
                    data={q: a[keep] for q, a in data.items()})
            self._probes = out
        return self._probes

    @property
    def energy(self) -> dict[str, np.ndarray]:
        """The energy ledger as a table: term -> array, one row a written frame, in the
        order of :data:`mpipd.model.ledger.TERMS` (``t`` first, the time in s; then the
        held and dissipated energies, the external and boundary work, the initial
        energy, all in J; ``balance`` last, the relative closure error).  Terms the
        file lacks are left out.  ``pandas.DataFrame(run.energy)`` makes it a data frame."""
        f = self._run.f
        if "energy" not in f:
            return {}
        names = [t for t in TERMS if t in f["energy"]]
        names += [t for t in f["energy"] if t not in names]
        return {t: self._run.energy(t) for t in names}

    # ------------------------------------------------------------ closing
    def close(self) -> None:
        """Close the file (collective under MPI)."""
        self._run.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def __repr__(self) -> str:
        return (f"RunFile({self.path!r}: {self.n_points} points, {self.frames} frames, "
                f"parts {self.parts})")


def open(path, comm=None) -> RunFile:
    """Open the run file ``path`` (a ``run.h5``, or the run folder holding it) for
    reading.  Serial without ``comm`` (no MPI); with an mpi4py communicator, every
    rank of it must call this, and reads its own slice of the points.  A file that is
    not an mpipd run file raises :class:`mpipd.post.reader.RunFileError` (one line)."""
    from pathlib import Path
    p = Path(path)
    if p.is_dir():
        p = p / "run.h5"
    return RunFile(p, comm)
