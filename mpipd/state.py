"""One State: the named per-point arrays of a rank, each registered by its owner.

Every model object (the solver itself, ``Correspondence``, each material
group, ``Failure``, ``InterfaceCorrection``, ``Gas``, the ledger, the peaks)
registers the arrays it owns when it is built::

    state.add("sigma", "correspondence", corr.sigma, checkpoint=True)

and nothing else reaches for them through attributes.  A :class:`Field` says

* ``owner``       who allocates and writes it (one owner per array);
* ``rows``        ``OWNED`` (one row per owned point), ``LOCAL`` (owned points
                  first, then ghosts), ``BOND`` (one entry per family bond), ``AUX``
                  (index lists, CSR offsets, per-pair lists: counted with the
                  point bytes), or an index array of owned points (a subset: one
                  material's points, the gas, the corrected interface points);
* ``exchanged``   whether the halo carries it to the ghosts every step (LOCAL
                  arrays only; tests/test_state.py checks the flag against the
                  halo's traffic);
* ``checkpoint``  whether checkpoints save it as ``points/<name>`` (its owned
                  rows, by global id; a subset's other rows are zeros) and, if so,
                  ``restore`` — when a restart loads it (see below);
* ``output``      the ``[output] fields`` name it is offered as, if any.

Checkpoint write and restore, the output fields and the memory report are loops
over this registry (mpipd.output.checkpoint, mpipd.output.writer,
:meth:`State.memory`).  A restart (mpipd.output.checkpoint.restore) runs

    1. load every ``STATE`` field             the state the next step needs
    2. each model's ``after_restore()``       rebuild what follows from it (K, damage, ...)
    3. load every ``REBUILT`` field           values the rebuild derives differently
                                              from the run (the fallback codes)
    4. ``Simulation.initialize()``            F and the forces of the restored state
    5. load every ``LAST`` field              the previous step's values that 4
                                              recomputes (a, F_old, the trapezoid's
                                              old forces)

Global scalars (the loads' work, the ledger's accumulated sums, the broken-bond
count) are registered the same way as :class:`Scalar` s and saved as checkpoint
attributes.

Arrays may be registered by value (the array itself) or by a getter (a
function returning the current array, for an owner that rebinds it); either way
the registry never copies.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

#: row kinds of a registered array (an index array of owned points is a subset)
OWNED, LOCAL, BOND, AUX, SUBSET = "owned", "local", "bond", "aux", "subset"
#: when a restart loads a checkpointed field (module docstring, steps 1, 3, 5)
STATE, REBUILT, LAST = "state", "rebuilt", "last"


@dataclass(frozen=True)
class Field:
    """One registered per-point (or per-bond) array; see the module docstring."""
    name: str
    owner: str
    get: Callable[[], np.ndarray]
    rows: object = OWNED
    exchanged: bool = False
    checkpoint: bool = False
    restore: str = STATE

    @property
    def array(self) -> np.ndarray:
        return self.get()

    @property
    def kind(self) -> str:
        """OWNED, LOCAL, BOND, AUX, or SUBSET (rows is an index array)."""
        return self.rows if isinstance(self.rows, str) else SUBSET

    def owned_values(self, n_owned: int) -> np.ndarray:
        """The field over the owned points, row = owned index (a subset: zeros elsewhere)."""
        a = self.get()
        if self.kind == LOCAL:
            return a[:n_owned]
        if self.kind == OWNED:
            return a
        full = np.zeros((n_owned,) + a.shape[1:], a.dtype)
        full[self.rows] = a
        return full

    def load(self, values: np.ndarray):
        """Inverse of :meth:`owned_values`: write owned-point values into the array."""
        a = self.get()
        if self.kind == LOCAL:
            a[:len(values)] = values
        elif self.kind == OWNED:
            a[:] = values
        else:
            a[:] = values[self.rows]


@dataclass(frozen=True)
class Scalar:
    """A global scalar saved as a checkpoint attribute.

    ``reduce = "sum"``: each rank holds its share; the checkpoint holds the sum and
    a restart gives it to rank 0 (others 0).  ``"same"``: every rank holds the
    same value.  ``"max"``: each rank holds its own running maximum; the checkpoint
    holds the largest and a restart gives it to every rank."""
    name: str
    owner: str
    get: Callable[[], float]
    set: Callable[[float], None]
    reduce: str = "sum"


@dataclass(frozen=True)
class Output:
    """A contribution to an ``[output] fields`` entry: ``value()`` over the owned
    points (rows ``rows`` of it, or all).  Several owners may offer one name (the
    pressure: JH2's points and the gas): the first assigns, the others add."""
    name: str
    owner: str
    value: Callable[[], np.ndarray]
    rows: object = OWNED


class State:
    """The registry of one rank (see the module docstring)."""

    def __init__(self, n_owned: int, n_local: int):
        self.n_owned = n_owned
        self.n_local = n_local
        self.fields: dict[str, Field] = {}
        self.scalars: dict[str, Scalar] = {}
        self.outputs: dict[str, list[Output]] = {}

    # ---------------------------------------------------------------- registration
    def add(self, name: str, owner: str, array=None, *, get=None, rows=OWNED,
            exchanged=False, checkpoint=False, restore=STATE,
            output: str | None = None) -> np.ndarray | None:
        """Register an array (or a getter of it) under ``name``; returns the array."""
        if name in self.fields:
            raise KeyError(f"state field {name!r} registered twice "
                           f"({self.fields[name].owner}, {owner})")
        if (array is None) == (get is None):
            raise TypeError("give the array or a getter of it, not both")
        if exchanged and not (isinstance(rows, str) and rows == LOCAL):
            raise ValueError(f"{name}: only a LOCAL array can be exchanged")
        if restore not in (STATE, REBUILT, LAST):
            raise ValueError(f"{name}: unknown restore phase {restore!r}")
        if get is None:
            get = (lambda a: (lambda: a))(array)
        self.fields[name] = Field(name, owner, get, rows, exchanged, checkpoint, restore)
        if output is not None:
            self.offer(output, owner, lambda f=self.fields[name]: f.owned_values(self.n_owned))
        return array

    def scalar(self, name: str, owner: str, get, set, reduce: str = "sum"):
        if name in self.scalars:
            raise KeyError(f"state scalar {name!r} registered twice")
        if reduce not in ("sum", "same", "max"):
            raise ValueError(f"{name}: unknown reduction {reduce!r}")
        self.scalars[name] = Scalar(name, owner, get, set, reduce)

    def offer(self, name: str, owner: str, value, rows=OWNED):
        """Offer ``value()`` (owned rows, or the subset ``rows``) as output field ``name``."""
        self.outputs.setdefault(name, []).append(Output(name, owner, value, rows))

    # ---------------------------------------------------------------- access
    def __getitem__(self, name: str) -> np.ndarray:
        return self.fields[name].get()

    def __contains__(self, name: str) -> bool:
        return name in self.fields

    def checkpointed(self, restore: str | None = None) -> list[Field]:
        """The checkpointed fields (of one restore phase), in registration order."""
        return [f for f in self.fields.values()
                if f.checkpoint and (restore is None or f.restore == restore)]

    def exchanged(self) -> list[Field]:
        return [f for f in self.fields.values() if f.exchanged]

    def output(self, name: str, width: int = 1) -> np.ndarray:
        """Output field ``name`` over the owned points (float64; ``width`` columns if
        > 1), from every owner that offers it: zeros where none does (a rank without
        a point of that material).  Subset offers assign their rows (the subsets of
        one name are disjoint: material groups); whole offers add."""
        out = None
        for o in self.outputs.get(name, ()):
            v = o.value()
            if isinstance(o.rows, str):
                out = np.array(v, dtype=np.float64) if out is None else out + v
            else:
                if out is None:
                    out = np.zeros((self.n_owned,) + v.shape[1:])
                out[o.rows] = v
        if out is None:
            out = np.zeros((self.n_owned,) if width == 1 else (self.n_owned, width))
        return out

    # ---------------------------------------------------------------- memory
    def memory(self) -> dict:
        """Bytes of the registered arrays: per owner, per-bond and per-point totals.
        An array registered twice (a view, a column of another) counts once."""
        seen, by_owner, bond, point = set(), {}, 0, 0
        for f in self.fields.values():
            a = f.get()
            if a is None:
                continue
            base = a
            while isinstance(base.base, np.ndarray):
                base = base.base
            if id(base) in seen:
                continue
            seen.add(id(base))
            by_owner[f.owner] = by_owner.get(f.owner, 0) + base.nbytes
            if f.kind == BOND:
                bond += base.nbytes
            else:
                point += base.nbytes
        return {"bond_bytes": bond, "point_bytes": point, "by_owner": by_owner}
