"""Named layouts shared by kernels, model objects, the CLI and postprocess.

Numba freezes module-level integers into the compiled code, so a kernel that
indexes ``fd[i, FD_H]`` compiles to the same arithmetic as ``fd[i, 9]``.

Force data ``fd`` (one row per local point, exchanged in the halo; DESIGN §4)::

    FD_B .. FD_B + 8   B = P K^-1 - h F, row-major (kernels.nosb.force_data)
    FD_H               hourglass coefficient h = 2 c M / tr K          (Eq. 15)
    FD_SPRING          1.0 while the point is on the bond-spring fallback, else 0.0
    FD_VISC_L          a C_l rho0 c0      (viscosity only, Eqs. 42–44)
    FD_VISC_Q          a C_q rho0 phi^2   (viscosity only)

Gas data ``gd`` (one row per local point, exchanged with ``fd``; kernels.ul)::

    GD_A .. GD_A + 5   A = -p M^-1, Voigt order (the gas's force state)
    GD_V               current volume
    GD_P               JWL pressure

Fallback codes ``spring`` (one per owned point; kernels.nosb):

    CORRESPONDENCE  K and F regular: the correspondence force
    SPRING_K        K not invertible (too few bonds left): bond springs, no F
    SPRING_F        F singular this step: bond springs (re-tested every step)
    NOT_TL          not a total-Lagrangian point (the gas): no F, no TL force

Failure modes ``mode`` (one per local point, exchanged; 0 = intact).
"""
from __future__ import annotations

# force data columns
FD_B = 0
FD_H = 9
FD_SPRING = 10
FD_VISC_L = 11
FD_VISC_Q = 12
#: width of fd without and with the artificial viscosity
FD_WIDTH = 11
FD_WIDTH_VISCOUS = 13

#: the interface correction's exchanged K^-1 (kernels.interface): 9 entries, then
#: a flag, 1.0 where the point has no correspondence force
KINV_FLAG = 9
KINV_WIDTH = 10

# gas data columns
GD_A = 0
GD_V = 6
GD_P = 7
GD_WIDTH = 8

# fallback codes
CORRESPONDENCE = 0
SPRING_K = 1
SPRING_F = 2
NOT_TL = 3

# failure modes
INTACT = 0
MODE_PLASTIC = 1        # JH2: damage D reached 1
MODE_TENSILE = 2        # JH2: p* < -T*
MODE_TENSION = 3        # the rate-dependent tension model (Eqs. 37–38)
#: short name of each mode, index = mode (the CLI's summary line)
MODE_NAMES = ("intact", "JH2 plastic", "JH2 tensile", "tension model")
#: label of each mode with its criterion, index = mode (figures, report keys)
MODE_LABELS = ("intact", "JH2 plastic (D >= 1)", "JH2 tensile (p < -T)",
               "tension model (Eq. 38)")
#: the number of modes including INTACT (length of a count vector)
N_MODES = 4
#: not a failure mode: the code an intact point on the bond springs carries only
#: while the materials update and the tension model runs, so that both skip it as
#: they skip a failed point (mpipd.model.correspondence.Correspondence.hold); never
#: seen outside those calls, never exchanged or written
MODE_HELD = 255
