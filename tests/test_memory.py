"""The memory model `mpipd check` reports equals what the solver allocates,
counted by walking every array the simulation holds."""
import pytest

from mpipd.check import BYTES_PER_BOND, BYTES_PER_GAS_POINT, BYTES_PER_UL_POINT, memory_model
from mpipd.input import scene as sc
from mpipd.solver import Simulation


@pytest.mark.parametrize("name,over", [
    ("elastic_wave", ["parts.0.dx=0.004"]),
    ("granite_ring", ["parts.0.dx=0.002"]),
    ("granite_ring", ["parts.0.dx=0.002", "time.multirate={max_ratio=8}", "output.every=40",
                      "time.t_end=1.6e-5"]),
    ("detonation_tube", ["parts.2.shape.radius=0.005"]),
])
def test_memory_model_matches_allocation(team, name, over):
    scene, _ = sc.load(name, over)
    sim = Simulation(scene, team)
    m = sim.memory()
    p = sim.points
    local, owned = memory_model(scene)
    model = local * p.n_local + owned * p.n_owned
    if sim.gas is not None:
        model += (BYTES_PER_GAS_POINT * len(sim.gas.gas_idx)
                  + BYTES_PER_UL_POINT * len(sim.gas.eligible)
                  + sim.gas.nbr.nbytes)         # the current families: not modelled
    actual = m["point_bytes"] + m["tree_bytes"]
    assert abs(actual - model) <= 0.01 * model + 4096, (actual, model)
    # the budget: 24 bytes a bond until the bonds' 1/|xi| (8 bytes) took a square root
    # and a division out of both bond loops (README, "Bond loops without data-decided
    # branches")
    assert m["bytes_per_bond"] == BYTES_PER_BOND <= 32
