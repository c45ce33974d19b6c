"""The interface every model family of the step pipeline implements.

A scene's materials name their model family (``Material.family``, the keys of
:data:`mpipd.solver.MODEL_FAMILIES`): "tl", the total-Lagrangian correspondence
solids (:class:`mpipd.model.correspondence.Correspondence`, every material of
:mod:`mpipd.materials` but the explosive), and "ul", the updated-Lagrangian
explosive gas (:class:`mpipd.model.gas.Gas`).  The solver builds one model per
family the scene uses and drives them all through these verbs, in this order
within a step (velocity Verlet, docs/architecture.md)::

    update(u, v, dt, t)     kinematics and stress (or pressure) of the owned points
    force_data(u, ledger)   -> the arrays whose owned rows the halo must copy to ghosts
    (one halo call for all models)
    gather(u, v, f, fv)     add the internal force density of the owned points to f
    commit()                end of the step: the state becomes the last step's

plus ``register(state)`` (its arrays in the State, once) and
``after_restore(halo)`` (what a restart rebuilds from the restored state).  A
model changes nothing outside its own arrays except ``f``/``fv`` in ``gather``
and the ledger's jumps in ``force_data``; the order of the models in the
solver's list is the order their forces are added (bit-for-bit results depend
on it).
"""
from __future__ import annotations


class Model:
    """Base class: every verb a no-op, so a model implements only what it does."""

    #: the State owner name of the model's arrays
    name = "model"

    def register(self, state):
        """Register this model's per-point arrays in the State."""

    def update(self, u, v, dt: float, t: float):
        """Advance the owned points' kinematics and stress to the end of the step
        (u, v: end-of-step displacement and mid-step velocity, ghosts current)."""

    def force_data(self, u, ledger) -> tuple:
        """Per-point data neighbours need for the force (owned rows filled here);
        returns the arrays the halo must move.  A discontinuous change of held
        energy made here is booked with ``ledger.book_jump``."""
        return ()

    def gather(self, u, v, f, fv):
        """Add the internal force density of the owned points to f (the viscous
        share also to fv)."""

    def commit(self):
        """The step's end state becomes the last step's."""

    def after_restore(self, halo):
        """Rebuild from a restored state what follows from it (restart)."""
