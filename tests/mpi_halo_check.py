"""Run under mpirun: every ghost receives a bitwise copy of its owner's values,
for float vectors, 3x3 tensors and uint8 flags.  Exits non-zero on failure."""
import sys

import numpy as np
from mpi4py import MPI

sys.path.insert(0, __file__.rsplit("/", 1)[0])
from conftest import make_scene, scene_dict  # noqa: E402

from mpipd.parallel.team import Team  # noqa: E402
from mpipd.solver import Simulation  # noqa: E402

dx = float(sys.argv[1])
team = Team(MPI.COMM_WORLD)
sim = Simulation(make_scene(scene_dict({"kind": "box", "lo": [0, 0, 0],
                                        "hi": [0.006, 0.005, 0.012]}, dx=dx)), team)
p = sim.points
n = p.n_owned
vec = np.full((p.n_local, 3), np.nan)
ten = np.full((p.n_local, 3, 3), np.nan)
flag = np.zeros(p.n_local, np.uint8)
g = p.gid.astype(float)
vec[:n] = np.stack([g, np.sqrt(g), np.sin(g)], axis=1)[:n]
ten[:n] = (g[:n, None, None] + np.arange(9).reshape(3, 3) / 7.0)
flag[:n] = (p.gid[:n] % 3 == 0)
sim.halo.exchange(vec, ten, flag)
ok = (np.array_equal(vec, np.stack([g, np.sqrt(g), np.sin(g)], axis=1))
      and np.array_equal(ten, g[:, None, None] + np.arange(9).reshape(3, 3) / 7.0)
      and np.array_equal(flag, (p.gid % 3 == 0).astype(np.uint8)))
n_ghost = p.n_local - n
all_ok = team.comm.allreduce(int(ok), op=MPI.MIN)
if team.root:
    print(f"halo ok={bool(all_ok)} ranks={team.size} peers={len(sim.halo.peers)}")
sys.exit(0 if all_ok and (team.size == 1 or n_ghost > 0) else 1)
