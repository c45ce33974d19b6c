"""The memory model `mpipd check` reports equals what the solver allocates."""
from conftest import make_scene, scene_dict

from mpipd.report import BYTES_PER_BOND, BYTES_PER_LOCAL_POINT, BYTES_PER_OWNED_POINT
from mpipd.solver import Simulation


def test_memory_model_matches_allocation(team):
    sim = Simulation(make_scene(scene_dict({"kind": "box", "lo": [0, 0, 0],
                                            "hi": [0.01, 0.008, 0.006]})), team)
    m = sim.memory()
    p = sim.points
    model = BYTES_PER_LOCAL_POINT * p.n_local + BYTES_PER_OWNED_POINT * p.n_owned
    assert 0 <= m["point_bytes"] - model <= 8          # + the last CSR offset
    assert m["bytes_per_bond"] == BYTES_PER_BOND
    assert m["bytes_per_bond"] <= 24
