"""What the verification problems share: the paper's granite, building a scene from
a dict, the stable step, and the wall time of the slowest rank."""
from __future__ import annotations

import math
import time

RHO, K_GR, G_GR = 2660.0, 21.9e9, 25.7e9          # the paper's granite (§3.1)
C_P = math.sqrt((K_GR + 4.0 * G_GR / 3.0) / RHO)


def granite():
    return {"model": "elastic", "density": RHO, "bulk_modulus": K_GR, "shear_modulus": G_GR}


def build_scene(d):
    from mpipd.input.scene import Scene
    from mpipd.input.schema import build
    return build(Scene, d)


def stable_step(scene) -> float:
    """The step `mpipd run` accepts at most (the Silling-Askari / CFL estimate)."""
    from mpipd.model.stability import critical_dt
    return critical_dt(scene)


class Timer:
    """Wall time of the slowest rank between start() and stop()."""

    def __init__(self, team):
        self.team = team

    def start(self):
        self.team.barrier()
        self.t0 = time.perf_counter()

    def stop(self) -> float:
        return self.team.max(time.perf_counter() - self.t0)


def timed_simulation(team, scene):
    """Start the clock (set-up counts as run time) and build the Simulation."""
    from mpipd.solver import Simulation
    tm = Timer(team)
    tm.start()
    return tm, Simulation(scene, team)
