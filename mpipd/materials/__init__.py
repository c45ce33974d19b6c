"""Constitutive models, one per module, behind one small interface.

A material is a frozen dataclass of its scene parameters, registered in
:data:`MATERIALS` under the name a scene's ``model`` key selects.  The
correspondence machinery (:mod:`mpipd.model.correspondence`) computes F, the rotation
R, the left stretch V and the *unrotated* rate of deformation d for every point;
a material only turns d and its own history into the unrotated Cauchy stress.

Interface (see :class:`mpipd.materials.base.Material`):

``density``, ``bulk_modulus``, ``shear_modulus``
    reference properties (used for the stable time step, the hourglass
    stiffness and the bond-spring fallback);
``new_state(n)``
    the material's history arrays for its ``n`` owned points (a dict; empty for
    elastic) — they exist only for points of this material;
``update(idx, d, J, dt, sigma, mode, state)``
    advance the unrotated stress ``sigma[idx]`` (Voigt order xx, yy, zz, yz,
    xz, xy) by one step from ``d[idx]`` and J = det F; points with
    ``mode[i] != 0`` have failed and are skipped; a model that detects failure
    sets ``mode[i]`` (1 JH2 plastic, 2 JH2 tensile) and zeroes the stress;
``tension``
    optional rate-dependent tension failure model (Eqs. 37–38, mode 3);
``can_fail``
    whether points of this material can fail (then bonds break);

A material's history arrays (``new_state``) are registered in the State by the
correspondence machinery as ``state<material id>/<name>`` (checkpointed; offered
as output fields by ``materials.base.STATE_OUTPUTS``); none is exchanged in the
halo (the force data carries what neighbours need).
"""
from ..input.schema import Registry

MATERIALS = Registry("material model", "model")

from . import elastic, j2, jh2, jwl  # noqa: E402,F401  (registers)
