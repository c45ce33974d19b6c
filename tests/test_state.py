"""The State registry (mpipd.state): every array a simulation holds is registered
with its owner, every checkpointed field round-trips through a checkpoint, the
``exchanged`` flag says exactly what the halo moves, and the registry refuses
ambiguous registrations."""
import numpy as np
import pytest
from conftest import SCENES

from mpipd.input import scene as sc
from mpipd.output import checkpoint as ck
from mpipd.parallel.halo import Halo
from mpipd.solver import Simulation
from mpipd.state import LOCAL, OWNED, State

#: arrays a Simulation holds that are not per-point state: the decomposition's
#: layer table and slab bounds (a few numbers per z level)
NOT_STATE = ("sim.slabs.",)


def reachable_arrays(root) -> dict:
    """Every NumPy array reachable from ``root`` through mpipd objects, dicts, lists
    and tuples (the independent count: what the old memory report walked), keyed by
    the id of the allocation it views."""
    seen, out = set(), {}

    def walk(obj, path, depth=0):
        if depth > 8 or id(obj) in seen:
            return
        seen.add(id(obj))
        if isinstance(obj, np.ndarray):
            base = obj
            while isinstance(base.base, np.ndarray):
                base = base.base
            out.setdefault(id(base), path)
            return
        if isinstance(obj, dict):
            for k, v in obj.items():
                walk(v, f"{path}[{k!r}]", depth + 1)
        elif isinstance(obj, (list, tuple)):
            for k, v in enumerate(obj):
                walk(v, f"{path}[{k}]", depth + 1)
        elif hasattr(obj, "__dict__") and obj.__class__.__module__.startswith("mpipd"):
            for k, v in vars(obj).items():
                if k != "state":
                    walk(v, f"{path}.{k}", depth + 1)
    walk(root, "sim")
    return out


def registered_bases(state) -> set:
    out = set()
    for f in state.fields.values():
        a = f.get()
        if a is None:
            continue
        while isinstance(a.base, np.ndarray):
            a = a.base
        out.add(id(a))
    return out


def build(name, over, team):
    scene, _ = sc.load(name, over)
    return Simulation(scene, team)


@pytest.mark.parametrize("name,over", SCENES, ids=[s[0] for s in SCENES])
def test_every_array_is_registered(team, name, over):
    """Nothing the simulation allocates is outside the registry (so the memory
    report, built from it, leaves nothing out), also after a few steps (the gas
    rebinds its families and positions)."""
    sim = build(name, over, team)
    for _ in range(3):
        sim.step()
        if sim.probes is not None:
            sim.probes.sample(sim.step_count, sim.t)
    found = reachable_arrays(sim)
    reg = registered_bases(sim.state)
    missing = sorted(path for k, path in found.items()
                     if k not in reg and not path.startswith(NOT_STATE))
    assert not missing, "arrays not registered in the State: " + ", ".join(missing)
    m = sim.memory()
    assert m["point_bytes"] > 0 and m["bond_bytes"] == sim.families.nbr.nbytes \
        + sim.families.broken.nbytes + sim.corr.omega_i.nbytes + sim.corr.omega_j.nbytes \
        + sim.corr.rinv.nbytes
    assert sum(m["by_owner"].values()) == m["point_bytes"] + m["bond_bytes"]


@pytest.mark.parametrize("name,over", SCENES, ids=[s[0] for s in SCENES])
def test_every_registered_array_is_c_contiguous(team, name, over):
    """Every registered array is, or is a column view of, a C-contiguous allocation
    (a point's row, a tensor's 9 numbers, adjacent in memory), at the start and
    after a few steps (arrays that are rebound): the kernels read them row by row.
    Columns of a packed per-point table (the gas data) are views by design."""
    def allocation(a):
        while isinstance(a.base, np.ndarray):
            a = a.base
        return a
    sim = build(name, over, team)
    for k in range(3):
        strided = sorted(f.name for f in sim.state.fields.values()
                         if f.get() is not None
                         and not allocation(f.get()).flags.c_contiguous)
        assert not strided, f"after {k} steps, not C-contiguous: " + ", ".join(strided)
        sim.step()


@pytest.mark.parametrize("name,over", SCENES[1:], ids=[s[0] for s in SCENES[1:]])
def test_every_checkpointed_field_round_trips(team, tmp_path, name, over):
    """Write a checkpoint after some steps, restore it into a new simulation of the
    same scene: every checkpointed field and scalar comes back bit for bit, and the
    next step of both is the same."""
    sim = build(name, over, team)
    for _ in range(4):
        sim.step()
    path = ck.write(sim, tmp_path / "c.h5", "scene text")
    new = build(name, over, team)
    ck.restore(new, path)
    n = sim.points.n_owned
    assert sim.state.checkpointed(), "no checkpointed field"
    for f in sim.state.checkpointed():
        a, b = f.owned_values(n), new.state.fields[f.name].owned_values(n)
        assert a.dtype == b.dtype and a.tobytes() == b.tobytes(), f.name
    for key, s in sim.state.scalars.items():
        assert s.get() == new.state.scalars[key].get(), key
    assert new.step_count == sim.step_count and new.t == sim.t
    sim.step()
    new.step()
    for key in ("u", "v", "sigma", "W"):
        assert np.array_equal(sim.state[key][:n], new.state[key][:n]), key


@pytest.mark.parametrize("name,over", SCENES, ids=[s[0] for s in SCENES])
def test_exchanged_flag_is_what_the_halo_moves(team, monkeypatch, name, over):
    """Every State array the halo carries in a (coarse) step is registered
    ``exchanged``, and every ``exchanged`` array is carried (the flag is not
    decoration)."""
    moved = set()
    real = Halo.exchange

    def spy(self, *arrays):
        for a in arrays:
            base = a
            while isinstance(base.base, np.ndarray):
                base = base.base
            moved.add(id(base))
        return real(self, *arrays)
    sim = build(name, over, team)
    monkeypatch.setattr(Halo, "exchange", spy)
    for _ in range(sim.classes.ratio):                  # to a coarse step (multi-rate):
        sim.step()                                      # the classes move there
    sim.check_finite()
    fields = {}
    for f in sim.state.fields.values():
        a = f.get()
        if a is None:                                   # made at first use: not yet
            continue
        while isinstance(a.base, np.ndarray):
            a = a.base
        fields.setdefault(id(a), []).append(f)
    flagged = {k for k, fs in fields.items() if any(f.exchanged for f in fs)}
    # what moved and is registered must be flagged; what is flagged must have moved
    moved_state = {k for k in moved if k in fields}
    assert moved_state == flagged, (
        sorted(f.name for k in moved_state - flagged for f in fields[k]),
        sorted(f.name for k in flagged - moved_state for f in fields[k]))


def test_registry_refuses_ambiguity():
    st = State(3, 5)
    st.add("u", "solver", np.zeros((5, 3)), rows=LOCAL, exchanged=True)
    with pytest.raises(KeyError, match="registered twice"):
        st.add("u", "other", np.zeros((5, 3)), rows=LOCAL)
    with pytest.raises(ValueError, match="only a LOCAL array"):
        st.add("w", "solver", np.zeros(3), rows=OWNED, exchanged=True)
    with pytest.raises(ValueError, match="restore phase"):
        st.add("x", "solver", np.zeros(3), checkpoint=True, restore="later")
    with pytest.raises(TypeError):
        st.add("y", "solver")


def test_subset_fields_and_outputs():
    """A subset field saves zeros outside its rows and loads only its rows; an output
    assembled from a subset and a whole-array offer is their sum, and an output no
    model offers on this rank is zeros of its width."""
    st = State(4, 6)
    rows = np.array([1, 3])
    hist = np.array([10.0, 30.0])
    st.add("h", "material 0", hist, rows=rows, checkpoint=True, output="pressure")
    st.offer("pressure", "gas", lambda: np.array([0.5, 0.0, 0.0, 0.0]))
    assert np.array_equal(st.fields["h"].owned_values(4), [0.0, 10.0, 0.0, 30.0])
    st.fields["h"].load(np.array([7.0, 8.0, 9.0, 6.0]))
    assert np.array_equal(hist, [8.0, 6.0])
    assert np.array_equal(st.output("pressure"), [0.5, 8.0, 0.0, 6.0])
    assert np.array_equal(st.output("stress", 6), np.zeros((4, 6)))
