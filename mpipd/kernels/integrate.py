"""Velocity-Verlet time integration (paper Eqs. 16–18) and energy sums.

    v_{n+1/2} = v_n + dt/2 a_n          (Eq. 16)
    u_{n+1}   = u_n + dt v_{n+1/2}      (Eq. 17)
    v_{n+1}   = v_{n+1/2} + dt/2 a_{n+1}  (Eq. 18)

Points with ``fixed[i]`` set keep u = 0 and v = 0.
"""
import numba

from .layout import CORRESPONDENCE


@numba.njit(cache=True)
def kick_drift(u, v, a, dt, fixed, damp, edamp):
    """Half kick then drift, owned points (rows of ``a``).

    Points with damp[i] = c > 0 (``damp`` may be empty) follow the damped update of
    Eq. 41, v_{n+1/2} = [(2 - c dt) v_{n-1/2} + 2 dt a_n] / (2 + c dt), written
    with v_n = v_{n-1/2} + dt/2 a_n as
    v_{n+1/2} = [(2 - c dt) v_n + (1 + c dt / 2) dt a_n] / (2 + c dt).

    That is the undamped half kick plus the velocity impulse
    delta = -kappa v_n, kappa = 2 c dt / (2 + c dt).  Against velocity Verlet's
    energy identity (kernels.energy) the impulse removes, per unit mass,
    -(v_n . delta + |delta|^2 / 2) = 4 c dt |v_n|^2 / (2 + c dt)^2 >= 0
    (-> c |v|^2 dt, the continuous damping power), accumulated in edamp[i].
    """
    h = 0.5 * dt
    damped = damp.shape[0] > 0
    book = edamp.shape[0] > 0
    for i in range(a.shape[0]):
        if fixed[i]:
            for c in range(3):
                v[i, c] = 0.0
            continue
        if damped and damp[i] > 0.0:
            cd = damp[i] * dt
            if book:
                edamp[i] += 4.0 * cd * (v[i, 0] ** 2 + v[i, 1] ** 2 + v[i, 2] ** 2) / (2.0 + cd) ** 2
            for c in range(3):
                v[i, c] = ((2.0 - cd) * v[i, c] + (1.0 + 0.5 * cd) * dt * a[i, c]) / (2.0 + cd)
                u[i, c] += dt * v[i, c]
            continue
        for c in range(3):
            v[i, c] += h * a[i, c]
            u[i, c] += dt * v[i, c]


@numba.njit(cache=True, inline="always")
def acceleration(f, rho, fixed, i, a):
    """a_i = f_i / rho_i (f the force density, rho the density), a_i = 0 at a fixed
    point; True if the point is free.  Newton's law of every kick, in one place."""
    if fixed[i]:
        for c in range(3):
            a[i, c] = 0.0
        return False
    s = 1.0 / rho[i]
    for c in range(3):
        a[i, c] = f[i, c] * s
    return True


@numba.njit(cache=True)
def accelerations(f, rho, fixed, rows, a):
    """:func:`acceleration` at the owned ``rows`` only (the forces gathered again
    there), without a kick."""
    for i in rows:
        acceleration(f, rho, fixed, i, a)


@numba.njit(cache=True)
def kick(v, f, rho, dt, fixed, a):
    """a = f / rho (:func:`acceleration`; v = 0 at a fixed point); second half kick
    v += dt/2 a."""
    h = 0.5 * dt
    for i in range(a.shape[0]):
        if not acceleration(f, rho, fixed, i, a):
            for c in range(3):
                v[i, c] = 0.0
            continue
        for c in range(3):
            v[i, c] += h * a[i, c]


@numba.njit(cache=True)
def stress_power(sigma, d, J, dt, spring, W, klass, level):
    """W += dt_i J sigma : d  (stress work per reference volume, elastic + plastic;
    P : Fdot = J sigma : D), dt_i = 2^k_i dt, at the points whose step class
    acts at ``level`` (kernels.classes).

    Called with dt/2 before and after the stress update, this is the
    trapezoidal rule on the stress power.
    """
    for i in range(W.shape[0]):
        if spring[i] != CORRESPONDENCE or klass[i] > level:
            continue
        s = (sigma[i, 0] * d[i, 0] + sigma[i, 1] * d[i, 1] + sigma[i, 2] * d[i, 2]
             + 2.0 * (sigma[i, 3] * d[i, 3] + sigma[i, 4] * d[i, 4] + sigma[i, 5] * d[i, 5]))
        W[i] += dt * float(1 << klass[i]) * J[i] * s


@numba.njit(cache=True)
def kinetic_energy(v, rho, vol):
    e = 0.0
    for i in range(rho.shape[0]):
        e += 0.5 * rho[i] * vol[i] * (v[i, 0] ** 2 + v[i, 1] ** 2 + v[i, 2] ** 2)
    return e


@numba.njit(cache=True)
def drive(u, v, idx, vel, dt):
    """v_i = vel[k] and u_i += dt vel[k] for i = idx[k]: the prescribed motion of
    driven points (mpipd.model.drive; dt = 0 sets the velocity only)."""
    for k in range(idx.shape[0]):
        i = idx[k]
        for c in range(3):
            v[i, c] = vel[k, c]
            u[i, c] += dt * vel[k, c]
