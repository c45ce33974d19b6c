"""Slab decomposition along the thickness axis z.

The model is a table of layers (:class:`mpipd.input.geometry.LayerTable`) in gid
order.  :func:`decompose` cuts it into ``n`` contiguous runs of whole z levels
with balanced point counts, so rank r owns one contiguous gid range.  A rank's
*ghosts* are every layer it does not own whose z lies within ``halo`` of its
own z range: ``halo = max horizon + max dx / 2`` covers the families of owned
points and the crossing-bond rule of bond breakage (paper §2.4).

A slab thinner than the halo is handled, not refused: ghosts may belong to any
rank within reach, not just the neighbours, and the halo exchanges directly
with each of them (see :mod:`mpipd.parallel.halo`).  Only a rank with no z level at all
is refused.

Replicated parts.  The explosive gas moves far from its reference slab, so it
is held whole on every rank (:func:`replicated_parts`).  The solids it acts on
(its ``interacts_with`` materials) are in its family wherever it goes: a gas
point owned by rank r may come within a horizon of a solid point whose layer is
beyond r's halo, and r must see that point as the 1-rank run does.  Those few
points come to r as remote rows, chosen afresh with the gas's Verlet list
(:class:`mpipd.parallel.near.NearHalo`).

Local layout on a rank: owned points first (gid order), then ghosts (gid
order).  Because owners hold contiguous gid ranges, the ghosts coming from one
rank — and the owned points going to one rank — are contiguous local slices.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..input.geometry import LayerTable, fill_layers
from ..kernels.influence import CODES as INFLUENCE
from ..state import LOCAL


class DecompositionError(ValueError):
    """The model cannot be split over the requested number of ranks."""


@dataclass(frozen=True)
class Slabs:
    table: LayerTable
    bounds: np.ndarray          # rank r owns layers [bounds[r], bounds[r+1])
    halo: float
    replicated: frozenset = frozenset()  # parts held whole on every rank (the gas)

    @property
    def n_ranks(self) -> int:
        return len(self.bounds) - 1

    def owned(self, r: int) -> tuple[int, int]:
        return int(self.bounds[r]), int(self.bounds[r + 1])

    def layer_of(self, gid) -> np.ndarray:
        """The layer of each global id."""
        return np.searchsorted(self.table.start, gid, side="right") - 1

    def owner_of_gid(self, gid) -> np.ndarray:
        """The rank that owns each global id."""
        return self.owner_of_layer(self.layer_of(gid))

    def holds(self, r: int, layer) -> np.ndarray:
        """Does rank r hold (own, or as a ghost) each of these layers?"""
        layer = np.asarray(layer)
        lo, hi = self.reach(r)
        held = (layer >= lo) & (layer < hi)
        if self.replicated:
            held |= np.isin(self.table.part[layer], list(self.replicated))
        return held

    def owner_of_layer(self, layer) -> np.ndarray:
        return np.searchsorted(self.bounds, layer, side="right") - 1

    def z_range(self, r: int) -> tuple[float, float]:
        a, b = self.owned(r)
        return float(self.table.z[a]), float(self.table.z[b - 1])

    def reach(self, r: int) -> tuple[int, int]:
        """Layers [lo, hi) within ``halo`` of rank r's slab (its own included)."""
        z0, z1 = self.z_range(r)
        z = self.table.z
        return (int(np.searchsorted(z, z0 - self.halo, side="left")),
                int(np.searchsorted(z, z1 + self.halo, side="right")))

    def ghost_layers(self, r: int) -> np.ndarray:
        """Static ghosts (within the halo), then every other replicated layer (by owner, gid)."""
        return np.concatenate((self.static_ghost_layers(r), self.replicated_layers_beyond(r)))

    def static_ghost_layers(self, r: int) -> np.ndarray:
        lo, hi = self.reach(r)
        a, b = self.owned(r)
        return np.concatenate((np.arange(lo, a), np.arange(b, hi)))

    def replicated_layers_beyond(self, r: int) -> np.ndarray:
        """Layers of the replicated parts outside rank r's reach (every rank holds them)."""
        if not self.replicated:
            return np.empty(0, np.int64)
        lo, hi = self.reach(r)
        L = np.arange(len(self.table.z))
        rep = np.isin(self.table.part, list(self.replicated))
        return L[rep & ((L < lo) | (L >= hi))]

    def points_of(self, r: int) -> tuple[int, int]:
        """(owned, ghost) point counts of rank r."""
        a, b = self.owned(r)
        owned = int(self.table.count[a:b].sum())
        ghost = int(self.table.count[self.ghost_layers(r)].sum())
        return owned, ghost

    def gid_range(self, r: int) -> tuple[int, int]:
        a, b = self.owned(r)
        return int(self.table.start[a]), int(self.table.start[a] + self.table.count[a:b].sum())

    def plan(self, r: int):
        """Halo plan of rank r: ``recv`` and ``send`` lists of (rank, start, stop)
        local index ranges, ordered by peer rank."""
        a, b = self.owned(r)
        ghosts = self.ghost_layers(r)
        counts = self.table.count
        n_owned = int(counts[a:b].sum())
        # local start of every ghost layer
        gstart = n_owned + np.concatenate(([0], np.cumsum(counts[ghosts])[:-1])).astype(np.int64)
        owner = self.owner_of_layer(ghosts)
        n_static = len(self.static_ghost_layers(r))
        recv = []
        for kind in (slice(0, n_static), slice(n_static, len(ghosts))):
            own = owner[kind]
            base = np.arange(len(ghosts))[kind]
            for q in np.unique(own):
                sel = base[own == q]
                start = int(gstart[sel[0]])
                recv.append((int(q), start, start + int(counts[ghosts[sel]].sum())))
        # receives come as one contiguous range per (peer, kind): static first, then replicated
        recv.sort(key=lambda e: (e[0], e[1]))
        ostart = np.concatenate(([0], np.cumsum(counts[a:b]))).astype(np.int64)
        send = []
        for q in range(self.n_ranks):
            if q == r:
                continue
            lo, hi = self.reach(q)
            slo, shi = max(lo, a), min(hi, b)
            if shi > slo:
                send.append((q, int(ostart[slo - a]), int(ostart[shi - a])))
            beyond = self.replicated_layers_beyond(q)
            mine = beyond[(beyond >= a) & (beyond < b)]
            if len(mine):
                idx = np.concatenate([np.arange(ostart[L - a], ostart[L - a + 1]) for L in mine])
                send.append((q, idx.astype(np.int64)))
        return recv, send


def decompose(table: LayerTable, n_ranks: int, halo: float, replicated=()) -> Slabs:
    """Split the layers into ``n_ranks`` slabs of whole z levels, balanced by points;
    the parts ``replicated`` (indices) are ghosts wherever they are not owned."""
    z = table.z
    # candidate cut positions: layer indices where z changes
    cuts = np.nonzero(np.diff(z) > 0)[0] + 1
    n_levels = len(cuts) + 1
    if n_ranks > n_levels:
        raise DecompositionError(
            f"the model has {n_levels} z levels; {n_ranks} ranks need at least one each "
            f"(use at most {n_levels} ranks or a finer dx)")
    cum = np.concatenate(([0], np.cumsum(table.count)))
    total = cum[-1]
    bounds = [0]
    for r in range(1, n_ranks):
        target = total * r / n_ranks
        # admissible cuts leave at least one level for each remaining rank
        lo_ok = np.searchsorted(cuts, bounds[-1], side="right")
        hi_ok = len(cuts) - (n_ranks - r - 1)
        cand = cuts[lo_ok:hi_ok]
        k = int(np.argmin(np.abs(cum[cand] - target)))
        bounds.append(int(cand[k]))
    bounds.append(len(z))
    return Slabs(table=table, bounds=np.asarray(bounds, dtype=np.int64), halo=float(halo),
                 replicated=frozenset(replicated))


@dataclass
class Points:
    """Struct of arrays of one rank's points: owned first, then ghosts, gid order in each."""
    x: np.ndarray               # (n_local, 3) reference positions
    gid: np.ndarray             # (n_local,) global ids
    part: np.ndarray            # (n_local,) part index
    material: np.ndarray        # (n_local,) material id
    volume: np.ndarray          # (n_local,)
    horizon: np.ndarray         # (n_local,)
    dx: np.ndarray              # (n_local,) local lattice spacing
    influence: np.ndarray       # (n_local,) uint8 influence-function code (kernels.influence)
    n_owned: int

    @property
    def n_local(self) -> int:
        return len(self.gid)

    def register(self, state):
        """The reference geometry in the State (owner "points"; never written)."""
        for name in ("x", "gid", "part", "material", "volume", "horizon", "dx", "influence"):
            state.add(name, "points", getattr(self, name), rows=LOCAL)


def local_points(scene, slabs: Slabs, r: int) -> Points:
    """Generate rank r's owned and ghost points — and nothing else."""
    a, b = slabs.owned(r)
    layers = np.concatenate((np.arange(a, b), slabs.ghost_layers(r)))
    x, part, gid = fill_layers(scene.parts, slabs.table, layers)
    mid = scene.material_ids
    dx = np.array([p.dx for p in scene.parts])[part]
    return Points(
        x=x, gid=gid, part=part,
        material=np.array([mid[p.material] for p in scene.parts], dtype=np.int32)[part],
        volume=dx ** 3,
        horizon=np.array([p.horizon for p in scene.parts])[part],
        dx=dx,
        influence=np.array([INFLUENCE[p.influence] for p in scene.parts], dtype=np.uint8)[part],
        n_owned=int(slabs.table.count[a:b].sum()),
    )


def replicated_parts(scene) -> list[int]:
    """Indices of the parts every rank holds whole: the explosive gas (``gas_materials``
    materials), which may move any distance from its owner's slab.  The solids it
    acts on are not replicated: the ones a gas point reaches beyond its owner's
    static halo come from their owners as remote rows (mpipd.parallel.near)."""
    gas = set(scene.gas_materials)
    return [k for k, q in enumerate(scene.parts) if q.material in gas]


def halo_width(scene) -> float:
    """Ghost region depth: the largest horizon plus half the largest dx (crossing bonds),
    plus twice the largest jitter offset (a jittered point is up to jitter * dx off its
    layer's z, mpipd.input.geometry)."""
    shift = max(q.jitter * q.dx for q in scene.parts)
    return scene.max_horizon + 0.5 * scene.max_dx + 2.0 * shift + 1e-9 * scene.max_dx
