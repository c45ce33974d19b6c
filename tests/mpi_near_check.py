"""Run under mpirun: the remote solid rows a rank receives (mpipd.parallel.near) are
exactly the solid points it does not hold that lie within the gas reach (horizon +
skin) of a gas point it owns, and each carries its owner's position, velocity,
volume and gid bitwise.  The gas is moved along z by up to the whole column
(deterministic in its gid, the same on every rank), so gas points sit far from
their owners' slabs.  Exits non-zero on failure."""
import sys

import numpy as np
from mpi4py import MPI

from mpipd.input import scene as sc
from mpipd.parallel.team import Team
from mpipd.solver import Simulation

team = Team(MPI.COMM_WORLD)
scene, _ = sc.load("detonation_tube", ["parts.2.shape.radius=0.005"])
sim = Simulation(scene, team)
p, g = sim.points, sim.gas
n, nl = p.n_owned, p.n_local
u = np.zeros((nl, 3))
gas = g.is_gas.astype(bool)
gg = p.gid[gas].astype(float)
u[gas, 2] = 0.016 * np.sin(gg * 0.7548776662466927) - 0.002   # up to a column away
u[gas, 0] = 1e-4 * np.cos(gg)
u[~gas] = 1e-5 * np.stack([np.sin(p.gid[~gas]), np.cos(p.gid[~gas]), np.sin(2.0 * p.gid[~gas])],
                          axis=1)
v = np.stack([np.sin(3.0 * p.gid), np.cos(5.0 * p.gid), p.gid * 1e-3], axis=1).astype(float)
y = p.x + u
g.search(y, v)
ye, ve = g.y_ext, g.v_ext
near = g.near
solid_owned = g.solids_owned
# every rank's owned solids (gid, y, v, volume), on every rank
allsol = team.comm.allgather((p.gid[solid_owned], y[solid_owned], v[solid_owned],
                              p.volume[solid_owned]))
sgid = np.concatenate([a[0] for a in allsol])
sy = np.concatenate([a[1] for a in allsol])
sv = np.concatenate([a[2] for a in allsol])
svol = np.concatenate([a[3] for a in allsol])
reach = g.reach + g.skin
mine = g.gas_idx
d = np.min(np.linalg.norm(sy[:, None, :] - y[mine][None, :, :], axis=2), axis=1) if len(mine) \
    else np.full(len(sgid), np.inf)
want = set(sgid[d < reach].tolist()) - set(p.gid.tolist())
got_gid = near.remote_gid if near is not None else np.zeros(0, np.int64)
ok = set(got_gid.tolist()) == want and len(got_gid) == len(want)
at = {gd: k for k, gd in enumerate(sgid)}
idx = np.array([at[int(q)] for q in got_gid], dtype=np.int64)
r = slice(nl, nl + len(got_gid))
ok = ok and np.array_equal(ye[r], sy[idx]) and np.array_equal(ve[r], sv[idx])
ok = ok and np.array_equal(g.vol_ext[r], svol[idx]) and np.array_equal(g.gid_ext[r], got_gid)
ok = ok and np.array_equal(ye[:nl], y) and np.array_equal(ve[:nl], v)
# every remote row's owner is another rank, and each source's rows are in gid order
for q, a, b in (near.recv if near is not None else []):
    ok = ok and q != team.rank and np.all(np.diff(g.gid_ext[a:b]) > 0)
n_remote = team.sum(len(got_gid))
all_ok = team.comm.allreduce(int(ok), op=MPI.MIN)
if team.root:
    print(f"near ok={bool(all_ok)} ranks={team.size} remote={n_remote}")
sys.exit(0 if all_ok and (team.size == 1 or n_remote > 0) else 1)
