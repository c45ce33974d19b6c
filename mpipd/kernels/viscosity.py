"""Artificial viscosity (paper Eqs. 42–44, after Silling et al. 2017).

Per point i: gamma_i = sum_j omega V_j (Eq. 43), the family's mean closing rate
phi_i = (1/gamma_i) sum_j omega Ydot . xi/|xi| V_j (Eq. 44), and v = rho0/rho = J.
The viscosity acts only on points whose family is being compressed
(phi_i < 0), like the von Neumann–Richtmyer q it imitates.

Eq. 42 as printed has no consistent units (1/(gamma delta) is m^-6).  mpipd
writes it as a viscous pressure q spread over the bonds the way the
correspondence model spreads an isotropic stress: for a pressure q a
correspondence point has the force state -omega q K^-1 xi ~= -3 q omega xi / tr K,
so the bond viscous state is

    T_v<xi> = (3 v^2 omega / tr K) (C_q rho0 phi^2 - C_l rho0 c0 Ydot . xi/|xi|) xi,

which is Eq. 42 with gamma delta -> tr K / (3 omega); it enters Eq. 1 on the
left, so the force on i is -sum_j (T_v,i<xi> - T_v,j<-xi>) V_j.  The linear term
is dissipative bond by bond; the quadratic one resists compression.
c0 = sqrt(K / rho0) is the bulk wave speed with the positive reference modulus.
Per point the halo carries fd[:, FD_VISC_L] = a C_l rho0 c0 and fd[:, FD_VISC_Q] = a C_q rho0 phi^2,
a = 3 v^2 / tr K (both zero where phi >= 0).
"""
import numba

from .layout import CORRESPONDENCE, FD_VISC_L, FD_VISC_Q


@numba.njit(cache=True)
def viscosity_data(dil, gamma, J, trK, spring, cl_rho_c, cq_rho, fd):
    """Fill fd[:, FD_VISC_L], fd[:, FD_VISC_Q] of owned points (see module docstring)."""
    for i in range(dil.shape[0]):
        fd[i, FD_VISC_L] = 0.0
        fd[i, FD_VISC_Q] = 0.0
        if spring[i] != CORRESPONDENCE or gamma[i] <= 0.0:
            continue
        phi = dil[i] / gamma[i]
        if phi < 0.0:
            a = 3.0 * J[i] * J[i] / trK[i]
            fd[i, FD_VISC_L] = a * cl_rho_c[i]
            fd[i, FD_VISC_Q] = a * cq_rho[i] * phi * phi


@numba.njit(cache=True, inline="always")
def viscous_bond(wi, wj, li, qi, lj, qj, dv0, dv1, dv2, e0, e1, e2, rinv):
    """Scalar c with T_v,i<xi> - T_v,j<-xi> = c xi (omega weights wi, wj; ``rinv`` = 1/|xi|);
    0 where both ends' coefficients are 0."""
    ydn = (dv0 * e0 + dv1 * e1 + dv2 * e2) * rinv
    return wi * (qi - li * ydn) + wj * (qj - lj * ydn)
