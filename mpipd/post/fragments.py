"""Fragments: connected components of the points over their intact bonds (issue 19).

A fragment is a connected component of the graph whose vertices are the
analysed points (the solid parts chosen, default the rock) and whose edges are
their intact bonds at a frame.  Failed points have lost every bond (bond
breakage from point failure), so each is a component of its own: they are
kept, not excluded, and counted with the *fines* — components of fewer than
``min_points`` points, below what the lattice resolves.  The bonds are the
model's own: the families are rebuilt from the run's scene with mpipd's lattice,
decomposition and family search (mpipd.model.families), and the frame's broken
bonds come from ``/bonds`` of the run file (mpipd.output.writer).  With
``damage_threshold`` d_c, a bond whose two ends both have damage > d_c also
counts as broken (PeriVis' rule; needs the ``damage`` field at the frame).

Labels, the same on any number of ranks (Harrison, Childs & Gaither 2011,
"Data-parallel mesh connected components labeling", EGPGV: local union-find,
then a merge of the components across process boundaries):

1. each rank joins its owned points over their intact bonds to owned points
   (union-find; every root is its component's smallest global id);
2. the roots of the ghost points come from their owners (a halo exchange);
3. every intact bond to a ghost gives a pair (local root, ghost root): the
   distinct pairs — a graph of the components that touch a slab face, not of
   the points — are gathered on rank 0, joined there and the root -> label map
   sent back.  A fragment's label is its smallest global id.

Per fragment, with m = rho V per point (and the point's own cube, dx^2 / 12 on
each axis of its second moment): the point count, volume V_f, mass, centre of
mass (of the current positions x + u when the frame holds ``u``), and the
second-moment tensor about the centre with eigenvalues l1 >= l2 >= l3.  Sizes:

    d_eq   = (6 V_f / pi)^(1/3)          the equivalent sphere,
    sieve  = 2 sqrt(5 l2)                the intermediate axis of the uniform
                                          ellipsoid of the same second moments
                                          (semi-axis a_i = sqrt(5 l_i)), the
                                          dimension a square mesh passes.

Sums are formed per z layer (in gid order) and the layers' partial sums added
in layer order on rank 0, so every number is bit-identical on any rank count.
"""
from __future__ import annotations

import numba
import numpy as np

from mpipd.input.geometry import LayerTable
from mpipd.model.families import build_families
from mpipd.parallel.decomp import decompose, halo_width, local_points
from mpipd.parallel.halo import Halo

#: columns of the per-fragment sums: n, V, m, m x (3), m x x^T (xx yy zz yz xz xy)
SUMS = 12


@numba.njit(cache=True)
def _find(parent, i):
    r = i
    while parent[r] != r:
        r = parent[r]
    while parent[i] != r:                       # path compression
        parent[i], i = r, parent[i]
    return r


@numba.njit(cache=True)
def local_roots(offsets, nbr, broken, keep, n_owned):
    """Union-find of the owned points over intact bonds between kept owned points;
    union by the smaller index, so a root is its component's smallest local index
    (= smallest gid: owned points are in gid order).  Returns the root of every
    owned point (-1 where not kept)."""
    parent = np.arange(n_owned)
    for i in range(n_owned):
        if not keep[i]:
            continue
        for b in range(offsets[i], offsets[i + 1]):
            j = nbr[b]
            if j >= n_owned or broken[b] or not keep[j]:
                continue
            ri, rj = _find(parent, i), _find(parent, j)
            if ri < rj:
                parent[rj] = ri
            elif rj < ri:
                parent[ri] = rj
    out = np.full(n_owned, -1, np.int64)
    for i in range(n_owned):
        if keep[i]:
            out[i] = _find(parent, i)
    return out


@numba.njit(cache=True)
def cross_pairs(offsets, nbr, broken, keep, n_owned, root_gid, ghost_root):
    """(root of i, root of ghost j) for every intact bond from a kept owned point i
    to a kept ghost j (root_gid: owned points' root gids; ghost_root: by local index)."""
    out = np.empty((nbr.shape[0], 2), np.int64)
    n = 0
    for i in range(n_owned):
        if not keep[i]:
            continue
        for b in range(offsets[i], offsets[i + 1]):
            j = nbr[b]
            if j < n_owned or broken[b] or not keep[j]:
                continue
            out[n, 0] = root_gid[i]
            out[n, 1] = ghost_root[j]
            n += 1
    return out[:n]


@numba.njit(cache=True)
def _break_damaged(offsets, nbr, damage, threshold, broken):
    """The damage rule: a bond whose two ends both have damage above ``threshold``
    counts as broken (no per-bond temporary)."""
    for i in range(offsets.shape[0] - 1):
        if damage[i] > threshold:
            for k in range(offsets[i], offsets[i + 1]):
                if damage[nbr[k]] > threshold:
                    broken[k] = 1


def merge_roots(pairs: np.ndarray) -> dict:
    """Union-find over (root, root) pairs: every root -> the smallest root joined to it."""
    parent = {}

    def find(a):
        while parent.get(a, a) != a:
            parent[a] = parent.get(parent[a], parent[a])
            a = parent[a]
        return a
    for a, b in pairs:
        ra, rb = find(int(a)), find(int(b))
        if ra != rb:
            lo, hi = min(ra, rb), max(ra, rb)
            parent[hi] = lo
            parent.setdefault(lo, lo)
    return {r: find(r) for r in list(parent)}


@numba.njit(cache=True)
def _layer_sums(label_idx, layer, x, m, cube, out):
    """out[f, l] += the point's sums (SUMS columns) for fragment index f, layer index l
    (points in gid order: each (f, l) cell is summed in gid order)."""
    for p in range(x.shape[0]):
        f, k = label_idx[p], layer[p]
        w = m[p]
        out[f, k, 0] += 1.0
        out[f, k, 1] += cube[p]
        out[f, k, 2] += w
        for a in range(3):
            out[f, k, 3 + a] += w * x[p, a]
        s = w * cube[p] ** (2.0 / 3.0) / 12.0          # the point's own cube: dx^2 / 12
        out[f, k, 6] += w * x[p, 0] * x[p, 0] + s
        out[f, k, 7] += w * x[p, 1] * x[p, 1] + s
        out[f, k, 8] += w * x[p, 2] * x[p, 2] + s
        out[f, k, 9] += w * x[p, 1] * x[p, 2]
        out[f, k, 10] += w * x[p, 0] * x[p, 2]
        out[f, k, 11] += w * x[p, 0] * x[p, 1]


class Fragments:
    """The fragments of one frame of a run (collective over ``team``)."""

    def __init__(self, scene, team, parts: list[int]):
        """``scene``: the run's (mpipd.input.scene.Scene); ``parts``: the indices of the
        parts analysed (solid parts)."""
        self.scene, self.team = scene, team
        table = LayerTable.from_parts(scene.parts, scene.material_ids)
        self.slabs = decompose(table, team.size, halo_width(scene))
        self.table = table
        p = self.points = local_points(scene, self.slabs, team.rank)
        recv, send = self.slabs.plan(team.rank)
        self.halo = Halo(team.comm, recv, send, p.n_owned, p.n_local)
        gas = set(scene.gas_parts)
        self.parts = [k for k in parts if k not in gas]      # the analysed parts
        self.keep = np.isin(p.part, self.parts)
        tl = ~np.isin(p.part, list(gas))
        self.families = build_families(p.x, p.gid, p.horizon, p.n_owned,
                                       tl=tl if gas else None)
        self.gid_range = self.slabs.gid_range(team.rank)
        a, b = self.slabs.owned(team.rank)
        # the layer of every owned point (layers are contiguous gid blocks)
        self.layer = np.repeat(np.arange(a, b), table.count[a:b])

    def mark_broken(self, pairs: np.ndarray, damage=None, threshold=None):
        """Set the families' broken flags from the frame's (gid_lo, gid_hi) pairs (those
        this rank may hold), and by the damage rule if ``threshold`` is given
        (``damage``: owned + ghost values).  Returns the number of pairs that are
        not bonds of the families (0 for the run's own file)."""
        p, fam = self.points, self.families
        missing = fam.set_broken(p.gid, pairs, both=True)
        if threshold is not None:
            _break_damaged(fam.offsets, fam.nbr, damage, threshold, fam.broken)
        return missing

    def labels(self) -> np.ndarray:
        """The fragment label (smallest gid) of every owned point; -1 where not analysed."""
        p, fam, team = self.points, self.families, self.team
        n = p.n_owned
        root = local_roots(fam.offsets, fam.nbr, fam.broken, self.keep, n)
        root_gid = np.where(root >= 0, p.gid[np.maximum(root, 0)], -1)
        ghost = np.full(p.n_local, -1, np.int64)
        ghost[:n] = root_gid
        self.halo.exchange(ghost)
        pairs = cross_pairs(fam.offsets, fam.nbr, fam.broken, self.keep, n, root_gid, ghost)
        pairs = np.unique(np.sort(pairs, axis=1), axis=0) if len(pairs) else pairs
        gathered = team.comm.gather(pairs, root=0)
        table = merge_roots(np.concatenate(gathered)) if team.root else None
        table = team.bcast(table)
        if table:
            keys = np.fromiter(table.keys(), np.int64, len(table))
            vals = np.fromiter(table.values(), np.int64, len(table))
            order = np.argsort(keys)
            keys, vals = keys[order], vals[order]
            pos = np.clip(np.searchsorted(keys, root_gid), 0, len(keys) - 1)
            hit = (keys[pos] == root_gid) & (root_gid >= 0)
            root_gid = np.where(hit, vals[pos], root_gid)
        return root_gid

    def statistics(self, label: np.ndarray, x: np.ndarray) -> dict:
        """Per-fragment sums on rank 0 (others: None), as arrays sorted by label:
        label, n, volume, mass, centre (3), second moment about the centre (3x3)."""
        p, team = self.points, self.team
        n = p.n_owned
        sel = label >= 0
        rho = np.array([self.scene.materials[m].density for m in self.scene.materials])
        mass = rho[p.material[:n]] * p.volume[:n]
        labs, idx = np.unique(label[sel], return_inverse=True)
        layers, lidx = np.unique(self.layer[sel], return_inverse=True)
        acc = np.zeros((len(labs), len(layers), SUMS))
        _layer_sums(idx.astype(np.int64), lidx.astype(np.int64), x[sel], mass[sel],
                    p.volume[:n][sel], acc)
        f, lay = np.nonzero(acc[:, :, 0])
        rows = (labs[f], layers[lay], acc[f, lay])
        got = team.comm.gather(rows, root=0)
        if not team.root:
            return None
        lab = np.concatenate([g[0] for g in got])
        lay = np.concatenate([g[1] for g in got])
        val = np.concatenate([g[2] for g in got])
        order = np.lexsort((lay, lab))                 # by label, then layer order
        lab, val = lab[order], val[order]
        uniq, start = np.unique(lab, return_index=True)
        tot = np.zeros((len(uniq), SUMS))
        ends = list(start[1:]) + [len(lab)]
        for r, (a, b) in enumerate(zip(start, ends)):   # layer partials added in layer order
            tot[r] = _ordered_sum(val[a:b])
        m = tot[:, 2]
        c = tot[:, 3:6] / m[:, None]
        S = np.empty((len(uniq), 3, 3))
        for a, (i, j) in enumerate(((0, 0), (1, 1), (2, 2))):
            S[:, i, j] = tot[:, 6 + a] / m - c[:, i] * c[:, j]
        for a, (i, j) in enumerate(((1, 2), (0, 2), (0, 1))):
            S[:, i, j] = S[:, j, i] = tot[:, 9 + a] / m - c[:, i] * c[:, j]
        return {"label": uniq, "n": tot[:, 0].astype(np.int64), "volume": tot[:, 1],
                "mass": m, "centre": c, "moment": S}


@numba.njit(cache=True)
def _ordered_sum(v):
    """Row sum from the first row to the last (the order is part of the result)."""
    s = np.zeros(v.shape[1])
    for r in range(v.shape[0]):
        s += v[r]
    return s


def sizes(stats: dict) -> dict:
    """d_eq = (6 V / pi)^(1/3) and sieve = 2 sqrt(5 l2) of every fragment, and the
    eigenvalues l1 >= l2 >= l3 of its second moment (module docstring)."""
    lam = np.sort(np.linalg.eigvalsh(stats["moment"]), axis=1)[:, ::-1]
    lam = np.maximum(lam, 0.0)
    return {"d_eq": np.cbrt(6.0 * stats["volume"] / np.pi),
            "sieve": 2.0 * np.sqrt(5.0 * lam[:, 1]), "lambda": lam}
