"""Parallel HDF5 output (h5py ``driver='mpio'``), written collectively by all ranks.

Layout (DESIGN §7), every per-point dataset indexed by **global id**, so a file
does not depend on the number of ranks that wrote it::

    /                       attrs: scene (TOML text), scene_name, mpipd_version,
                            git_commit, ranks, dt, steps, n_points, n_bonds,
                            frames_written
    /geometry/x             (N, 3) reference positions
    /geometry/volume        (N,)
    /geometry/material      (N,)  material id (attrs: names)
    /geometry/part          (N,)  part index (attrs: names)
    /geometry/z_level       (N,)  the z of each point's lattice level (only when a part
                            is jittered: the points are off their levels)
    /geometry/strength_factor (N,) a heterogeneous material's strength factor (1
                            elsewhere; only if some material has one,
                            mpipd.materials.heterogeneity)
    /fields/<name>          (n_frames, N[, k])   u, v, stress, stress_work, elastic_energy,
                                                 peak_* (running peaks), ...
    /time                   (n_frames,)
    /energy/<term>          (n_frames,)  the energy ledger (mpipd.model.ledger.TERMS)
    /probes/<name>/{t, sigma_rr, v_r, p, s, strength}          (n_steps + 1,), row = step
    /bonds/broken           (M, 2) int64: the broken bonds of every frame as (gid_lo,
                            gid_hi) pairs, gid_lo < gid_hi, each bond once; frame k's
                            set is rows offsets[k]:offsets[k + 1] (sorted by gid_lo);
                            only in a scene that can fail or has joints
    /bonds/offsets          (n_frames + 1,) int64
    /xdmf/vertices          (N,) int64: the gids 0 .. N-1, the connectivity of run.xdmf's
                            Polyvertex (one vertex cell a point); written once, at the
                            first close
    attrs peak_gas_pressure, density_at_lighting (JSON: per charge, the largest and
                            mean density when lit, x the charge's, and the fraction lit)

Each rank owns one contiguous gid range and writes it as one hyperslab.

``run.xdmf`` beside the file (written by rank 0 when the writer closes, so at the
end of a run, of a ``--stop-after`` and of a restart, for the frames written so
far) opens every field at every frame in ParaView: one Uniform grid a frame in a
temporal collection, the points on ``/geometry/x`` (gid order) each a vertex cell (a
Polyvertex of N one-point elements whose connectivity is ``/xdmf/vertices``: without
it the Xdmf 3 readers give no cells, and nothing draws, thresholds or clips), each
field a selection of frame k of ``/fields/<name>``, spelled so that all three of
ParaView 5.11's XDMF readers load it (``XDMFReader``, ``Xdmf3ReaderS``,
``Xdmf3ReaderT``; see ``_xdmf_field_item``).
"""
from __future__ import annotations

import json
import subprocess
from pathlib import Path
from xml.sax.saxutils import quoteattr

import numpy as np

from .. import __version__
from ..input.scene import OUTPUT_FIELDS
from ..kernels.linalg import VOIGT
from ..model.ledger import DISSIPATED, HELD, TERMS

#: the suffix of a commit whose solver files had uncommitted changes at run time
DIRTY = "-dirty"


def git_commit(where: Path | None = None) -> str:
    """HEAD of the checkout that holds ``where`` (default: the solver package), with
    ``DIRTY`` appended if a tracked file under ``where`` differs from it: a run made
    from uncommitted solver code does not pass for the commit's."""
    where = Path(where) if where is not None else Path(__file__).resolve().parents[1]
    try:
        out = subprocess.run(["git", "-C", str(where), "rev-parse", "HEAD"],
                             capture_output=True, text=True, timeout=5)
        if out.returncode != 0:
            return "unknown"
        st = subprocess.run(["git", "-C", str(where), "status", "--porcelain",
                             "--untracked-files=no", "."],
                            capture_output=True, text=True, timeout=10)
        dirty = st.returncode != 0 or bool(st.stdout.strip())
        return out.stdout.strip() + (DIRTY if dirty else "")
    except (OSError, subprocess.SubprocessError):
        return "unknown"


def short_commit(commit: str, n: int = 12) -> str:
    """The first ``n`` characters of a recorded commit, keeping its ``DIRTY`` mark."""
    commit = str(commit)
    return commit[:n] + (DIRTY if commit.endswith(DIRTY) and len(commit) - len(DIRTY) > n else "")


def n_frames(n_steps: int, every: int) -> int:
    """Frames at step 0, every ``every`` steps, and the last step."""
    return n_steps // every + 1 + (1 if n_steps % every else 0)


def field_values(sim, name: str) -> np.ndarray:
    """Output field ``name`` over the owned points (gid order), as the State's
    owners offer it (mpipd.state.State.output)."""
    return sim.state.output(name, OUTPUT_FIELDS[name][0])


#: bytes of one chunk of a frame dataset (a frame is split into chunks of about this size)
CHUNK_BYTES = 1 << 22


def growable(shape) -> dict:
    """Options of a frame (or probe) dataset that a restart can resize along axis 0:
    chunked, one frame a chunk row, about CHUNK_BYTES a chunk; unwritten rows are NaN."""
    rest = shape[2:] if len(shape) > 2 else ()
    width = int(np.prod(rest)) if rest else 1
    if len(shape) == 1:
        chunks = (max(1, min(shape[0], CHUNK_BYTES // 8)),)
    else:
        chunks = (1, max(1, min(shape[1], CHUNK_BYTES // (8 * width))), *rest)
    return {"maxshape": (None, *shape[1:]), "chunks": chunks, "fillvalue": np.nan}


class Writer:
    """Collective writer of one run file.  All ranks call every method."""

    def __init__(self, path, sim, scene_text: str, n_steps: int, resume: bool = False,
                 run_id: str = ""):
        """Create the run file for run ``run_id`` — or, with ``resume``, reopen it and
        continue after the frames up to the simulation's current step (restart).
        A restart may change the run length: the frame and probe datasets grow or
        shrink along their first axis (mpipd.output.rundir.check_restart refuses the rest)."""
        import h5py
        self.path = Path(path)
        self.sim = sim
        scene = sim.scene
        self.every = scene.output.every
        self.fields = scene.output.fields
        self.n_frames = n_frames(n_steps, self.every)
        self.frame_no = 0
        self.held = 0
        comm = sim.team.comm
        self.commit = sim.team.bcast(git_commit() if sim.team.root else None)
        if resume:
            self.f = h5py.File(self.path, "r+", driver="mpio", comm=comm)
            self.run_id = str(self.f.attrs["run_id"])
            # the scene attribute stays the run's: a restart changes no physics
            # (rundir.check_same_physics); its own --set are in its ``segments`` entry
            self.dsets = {name: self.f["fields"][name] for name in self.fields}
            self.time = self.f["time"]
            self.energy = {k: self.f["energy"][k] for k in self.f["energy"]}
            self.frame_no = sim.step_count // self.every + 1
            # frames the file holds beyond the checkpoint (a run killed after it) stay
            # counted until they are written again (rundir.check_frames keeps them in
            # the new run length)
            self.held = int(self.f.attrs.get("frames_written", 0))
            self.bonds = self.f["bonds"] if "bonds" in self.f else None
            if self.time.shape[0] != self.n_frames:          # a new run length
                for d in (*self.dsets.values(), self.time, *self.energy.values()):
                    d.resize(self.n_frames, axis=0)
                if self.bonds is not None:
                    self.bonds["offsets"].resize(self.n_frames + 1, axis=0)
            if int(self.f.attrs["steps"]) != n_steps:
                self.f.attrs["steps"] = n_steps
            if self.bonds is not None:       # frames after the checkpoint are written again
                # (the rows past it stay until then: a restart stopped before them
                # keeps those frames whole; _broken_bonds resizes from here)
                self.bond_rows = int(self.bonds["offsets"][self.frame_no])
            if sim.probes is not None:
                sim.probes.create(self.f, n_steps + 1)
            return
        self.f = h5py.File(self.path, "w", driver="mpio", comm=comm)
        N = sim.n_global
        a = self.f.attrs
        self.run_id = run_id
        a["run_id"] = run_id
        a["every"] = self.every
        a["scene"] = scene_text
        a["scene_name"] = scene.name
        a["mpipd_version"] = __version__
        a["git_commit"] = self.commit
        a["ranks"] = sim.team.size
        a["dt"] = sim.dt
        a["steps"] = n_steps
        a["n_points"] = N
        a["n_bonds"] = sim.n_bonds_global
        a["joint_bonds"] = sim.joint_bonds          # broken from the start (mpipd.input.joints)
        a["frames_written"] = 0
        g0, g1 = sim.gid_range
        n = sim.points.n_owned
        p = sim.points
        geo = self.f.create_group("geometry")
        self._write(geo.create_dataset("x", (N, 3), "f8"), np.s_[g0:g1], p.x[:n])
        self._write(geo.create_dataset("volume", (N,), "f8"), np.s_[g0:g1], p.volume[:n])
        dm = geo.create_dataset("material", (N,), "i4")
        dm.attrs["names"] = list(scene.materials)
        self._write(dm, np.s_[g0:g1], p.material[:n])
        dp = geo.create_dataset("part", (N,), "i4")
        dp.attrs["names"] = [q.name for q in scene.parts]
        self._write(dp, np.s_[g0:g1], p.part[:n])
        if any(q.jitter > 0 for q in scene.parts):     # the lattice levels (mpipd.post)
            t, (a0, b0) = sim.slabs.table, sim.slabs.owned(sim.team.rank)
            self._write(geo.create_dataset("z_level", (N,), "f8"), np.s_[g0:g1],
                        np.repeat(t.z[a0:b0], t.count[a0:b0]))
        for name, values in sim.geometry_fields().items():
            self._write(geo.create_dataset(name, (N,), "f8"), np.s_[g0:g1], values)
        fg = self.f.create_group("fields")
        self.dsets = {}
        for name in self.fields:
            k = OUTPUT_FIELDS[name][0]
            shape = (self.n_frames, N) if k == 1 else (self.n_frames, N, k)
            self.dsets[name] = fg.create_dataset(name, shape, "f8", **growable(shape))
        self.time = self.f.create_dataset("time", (self.n_frames,), "f8",
                                          **growable((self.n_frames,)))
        eg = self.f.create_group("energy")
        eg.attrs["doc"] = (f"energy ledger (J), see mpipd.model.ledger: held = {' + '.join(HELD)}; "
                           f"dissipated = {' + '.join(DISSIPATED)}; balance = "
                           "(initial + external + boundary - held - dissipated) / scale")
        self.energy = {k: eg.create_dataset(k, (self.n_frames,), "f8",
                                            **growable((self.n_frames,))) for k in TERMS}
        self.bonds, self.bond_rows = None, 0
        if sim.failure is not None or sim.joint_bonds:
            self.bonds = self.f.create_group("bonds")
            self.bonds.create_dataset("broken", (0, 2), "i8", maxshape=(None, 2),
                                      chunks=(65536, 2))
            off = self.bonds.create_dataset("offsets", (self.n_frames + 1,), "i8",
                                            **{**growable((self.n_frames + 1,)),
                                               "fillvalue": -1})       # -1: not written
            self._write(off, np.s_[0:1], np.zeros(1, np.int64))
        if sim.probes is not None:
            sim.probes.create(self.f, n_steps + 1)

    @staticmethod
    def _write(dset, sel, data):
        with dset.collective:
            dset[sel] = data

    def frame(self, sim):
        """Write the current state as the next frame; returns the ledger reading
        it recorded (mpipd.model.ledger.Energies, global)."""
        if self.frame_no >= self.n_frames:
            raise RuntimeError("more frames than the file was sized for")
        k = self.frame_no
        g0, g1 = sim.gid_range
        for name, d in self.dsets.items():
            self._write(d, np.s_[k, g0:g1], field_values(sim, name))
        e = sim.energies()
        values = {"t": sim.t, **e.as_dict()}
        # small per-frame scalars: every rank writes the same value collectively
        self._write(self.time, np.s_[k:k + 1], np.array([sim.t]))
        for key, d in self.energy.items():
            self._write(d, np.s_[k:k + 1], np.array([values[key]]))
        if self.bonds is not None:
            self._broken_bonds(sim, k)
        self.frame_no += 1
        if sim.probes is not None:
            sim.probes.flush()
        self.f.attrs["frames_written"] = self.frames_written
        self.f.flush()                  # a crash loses at most the frames since this one
        return e

    def _broken_bonds(self, sim, k: int):
        """Append frame k's broken bonds to /bonds/broken (each rank its owned
        points' lower-gid copies, in rank = gid order: the rows come out sorted)."""
        pairs = sim.families.broken_pairs(sim.points.gid, lower=True)
        counts = sim.team.gather(len(pairs))
        start = self.bond_rows + int(sum(counts[:sim.team.rank]))
        self.bond_rows += int(sum(counts))
        d = self.bonds["broken"]
        d.resize(self.bond_rows, axis=0)                 # collective
        # independent I/O: a collective write hangs when one rank has nothing to write
        if len(pairs):
            d[start:start + len(pairs)] = pairs
        self._write(self.bonds["offsets"], np.s_[k + 1:k + 2], np.array([self.bond_rows]))

    def close(self, segment: dict | None = None):
        """Finish the file.  ``segment`` (this invocation's first and last step, ranks,
        loop wall time, throughput) is appended to the JSON list attr ``segments``
        with the commit that ran it, so a run's cost survives its restarts."""
        if self.sim.probes is not None:
            self.sim.probes.flush()
        if segment is not None:
            old = self.f.attrs.get("segments", "[]")
            segs = json.loads(old if isinstance(old, str) else old.decode())
            segs.append({**segment, "git_commit": self.commit})
            self.f.attrs["segments"] = json.dumps(segs)
        self._vertices()
        self.f.attrs["frames_written"] = self.frames_written
        self.f.attrs["bonds_broken"] = self.sim.bonds_broken()
        self.f.attrs["failed_points_by_mode"] = self.sim.failure_counts()
        if self.sim.gas is not None:    # every step's peak, not just the frames' (since start/restart)
            self.f.attrs["peak_gas_pressure"] = self.sim.team.max(self.sim.gas.peak_pressure)
            # per charge: density when lit, x the charge's (mpipd.model.gas.Gas.lit_density)
            self.f.attrs["density_at_lighting"] = json.dumps(
                self.sim.gas.lit_density(self.sim.team))
        self.f.close()
        if self.sim.team.root:
            times, geometry = self.time_values()
            scene = self.sim.scene
            parts = [{"name": q.name, "material": q.material,
                      "gas": q.material in scene.gas_materials} for q in scene.parts]
            write_xdmf(self.path, self.sim.n_global, self.fields, self.frames_written,
                       times, self.n_frames, geometry, parts)

    def _vertices(self):
        """``/xdmf/vertices``, the gids 0 .. N-1: the connectivity of the Polyvertex
        in run.xdmf (``write_xdmf``).  Written once, collectively, each rank its gid
        range like the geometry; a close that finds it (a restart's) writes nothing,
        and a file from before it gets it at its restart's close."""
        if "xdmf/vertices" in self.f:
            return
        g0, g1 = self.sim.gid_range
        d = self.f.require_group("xdmf").create_dataset("vertices", (self.sim.n_global,), "i8")
        self._write(d, np.s_[g0:g1], np.arange(g0, g1, dtype=np.int64))

    @property
    def frames_written(self) -> int:
        """Frames the file holds: this invocation's, or more when a restart has not
        yet reached the frames an earlier invocation wrote after its checkpoint."""
        return max(self.frame_no, self.held)

    def time_values(self):
        """The frames' times and the per-point geometry datasets (name -> "Int" or
        "Float"), read back by rank 0 for the XDMF file."""
        import h5py
        with h5py.File(self.path, "r") as f:
            geo = {k: ("Int" if d.dtype.kind == "i" else "Float")
                   for k, d in f["geometry"].items() if d.ndim == 1}
            return f["time"][: self.frames_written], geo


def _xdmf_field_item(h5: str, name: str, k: int, shape, column: int | None = None) -> list:
    """The DataItem of frame ``k`` of ``/fields/<name>`` (dataset shape ``shape``).

    ParaView 5.11's XDMF readers sit on two libraries, and each library reads a
    frame's slice in only one spelling (measured with pvbatch; ``tests/test_paraview.py``
    checks all three readers):

    * ``XDMFReader`` (libxdmf2) understands a HyperSlab DataItem (children: the
      start/stride/count selection and the whole dataset).  It also accepts the
      Xdmf 1 spelling ``Type="HyperSlab"`` for ``ItemType``.
    * ``Xdmf3ReaderS``/``Xdmf3ReaderT`` (libxdmf3; ``OpenDataFile`` picks
      ``Xdmf3ReaderS`` for ``.xdmf``) load no HyperSlab item, at any frame: VTK asks
      the array's number type before reading it, and a HyperSlab, a reference to
      another item, has none yet, so each field is dropped with "Skipping
      unrecognized array type [None]".  They do read Xdmf 3's own selection syntax
      in an HDF item's text, ``file:/dataset|start:stride:count:dataspace``.

    So the item carries both: ``Type="HyperSlab"`` (libxdmf2 takes it as a HyperSlab
    and reads the two children; Xdmf 3 reads only ``ItemType`` and so takes a plain
    HDF item), and as its text, before the children, the Xdmf 3 selection (which is
    what Xdmf 3 takes as the item's content; libxdmf2 ignores a HyperSlab's text).
    """
    rank = len(shape)
    start = (k,) + (0,) * (rank - 1)
    stride = (1,) * rank
    count = (1,) + tuple(shape[1:])
    dims = " ".join(map(str, shape[1:]))            # one frame: N or N k
    if column is not None:                          # one column of an (F, N, k) field
        start, count, dims = (k, 0, column), (1, shape[1], 1), str(shape[1])

    def j(v):
        return " ".join(map(str, v))
    return [f'<DataItem Type="HyperSlab" Dimensions="{dims}" NumberType="Float" Precision="8" '
            f'Format="HDF">{h5}:/fields/{name}|{j(start)}:{j(stride)}:{j(count)}:{j(shape)}',
            f'<DataItem Dimensions="3 {rank}" NumberType="Int" Format="XML">'
            f'{j(start)} {j(stride)} {j(count)}</DataItem>',
            f'<DataItem Dimensions="{j(shape)}" NumberType="Float" Precision="8" '
            f'Format="HDF">{h5}:/fields/{name}</DataItem>',
            "</DataItem>"]


def write_xdmf(h5path: Path, N: int, fields, frames: int, times, n_alloc: int | None = None,
               geometry: dict | None = None, parts: list | None = None) -> Path:
    """An XDMF file next to ``h5path`` describing frames ``0 .. frames-1`` as point clouds.

    The points of a frame are a Polyvertex of ``N`` one-point elements, point ``i`` the
    element ``i``, with its connectivity ``/xdmf/vertices`` (``Writer._vertices``).
    ParaView's Xdmf 3 readers (``Xdmf3ReaderS``, the one ``OpenDataFile`` picks, and
    ``Xdmf3ReaderT``) make cells only from a topology's connectivity: without it they
    gave the points and no cell, so Surface and Points drew nothing and Threshold, Clip
    and Slice gave nothing.  Now all three readers give N vertex cells (libxdmf2's
    ``XDMFReader`` did without).  An inline XML index array would do on a small run, but
    libxml2 refuses a text node over 10 MB (about 1.2 M points) and every frame would
    carry it; the HDF5 dataset is written once.

    ``n_alloc`` is the length of the fields' frame axis in the file (the frames the
    run was sized for, default ``frames``): a run stopped early has written fewer.
    Each frame's fields are selections of ``/fields/<name>``, readable by all three
    of ParaView's XDMF readers (see ``_xdmf_field_item``); the HDF5 layout is the
    one the rest of mpipd reads.  ``geometry``: the per-point datasets of
    ``/geometry`` (name -> "Int" or "Float"), each an attribute of every frame.
    ``parts``: per part index, its ``name``, ``material`` and whether it is an
    explosive's ``gas``, as JSON in the Domain's ``<Information Name="parts">``
    (which the readers skip; scripts/paraview_figure.py hides the gas with it)."""
    h5 = h5path.name
    out = h5path.with_suffix(".xdmf")
    n_alloc = frames if n_alloc is None else n_alloc
    lines = ['<?xml version="1.0" ?>', '<Xdmf Version="3.0">', "<Domain>"]
    if parts is not None:
        lines.append(f'<Information Name="parts" Value={quoteattr(json.dumps(parts))}/>')
    lines.append('<Grid Name="run" GridType="Collection" CollectionType="Temporal">')
    for k in range(frames):
        lines += [f'<Grid Name="frame{k}" GridType="Uniform">',
                  f'<Time Value="{times[k]:.9e}"/>',
                  f'<Topology TopologyType="Polyvertex" NumberOfElements="{N}" '
                  'NodesPerElement="1">',
                  f'<DataItem Dimensions="{N}" NumberType="Int" Precision="8" '
                  f'Format="HDF">{h5}:/xdmf/vertices</DataItem>', "</Topology>",
                  '<Geometry GeometryType="XYZ">',
                  f'<DataItem Dimensions="{N} 3" NumberType="Float" Precision="8" '
                  f'Format="HDF">{h5}:/geometry/x</DataItem>', "</Geometry>"]
        for name, kind in (geometry or {}).items():
            prec = "4" if kind == "Int" else "8"
            lines += [f'<Attribute Name="{name}" AttributeType="Scalar" Center="Node">',
                      f'<DataItem Dimensions="{N}" NumberType="{kind}" Precision="{prec}" '
                      f'Format="HDF">{h5}:/geometry/{name}</DataItem>', "</Attribute>"]
        for name in fields:
            kk = OUTPUT_FIELDS[name][0]
            # stress: the file's 6 columns, xx yy zz yz xz xy (ParaView names the
            # components of a 6-column array XX YY ZZ XY YZ XZ), so each component
            # is also a scalar named stress_xx ... stress_xy
            kind = {1: "Scalar", 3: "Vector", 6: "Matrix"}[kk]
            shape = (n_alloc, N) if kk == 1 else (n_alloc, N, kk)
            lines += [f'<Attribute Name="{name}" AttributeType="{kind}" Center="Node">',
                      *_xdmf_field_item(h5, name, k, shape), "</Attribute>"]
            if kk == 6:           # and each component by its name, ParaView's labels aside
                for c, comp in enumerate(VOIGT):
                    lines += [f'<Attribute Name="{name}_{comp}" AttributeType="Scalar" '
                              'Center="Node">', *_xdmf_field_item(h5, name, k, shape, c),
                              "</Attribute>"]
        lines.append("</Grid>")
    lines += ["</Grid>", "</Domain>", "</Xdmf>"]
    out.write_text("\n".join(lines) + "\n")
    return out
