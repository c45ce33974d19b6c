"""Layer table, gid order, slab balance, ghost reach and halo plans (no MPI needed)."""
import numpy as np
import pytest
from conftest import granite, make_scene, scene_dict

from mpipd.input.geometry import LayerTable, fill_layers
from mpipd.model.families import build_families
from mpipd.parallel.decomp import DecompositionError, decompose, halo_width, local_points


def two_part_scene():
    parts = [
        {"name": "rock", "material": "rock", "dx": 1e-3,
         "shape": {"kind": "annulus", "center": [0, 0], "inner_radius": 0.003,
                   "radius": 0.008, "z": [0, 0.012]}},
        {"name": "core", "material": "steel", "dx": 1e-3,
         "shape": {"kind": "cylinder", "center": [0, 0], "radius": 0.0025, "z": [0, 0.012]}},
    ]
    d = scene_dict(None, parts=parts)
    d["materials"] = {"rock": granite(), "steel": granite(density=7800.0)}
    return make_scene(d)


def test_gids_follow_z_material_y_x():
    scene = two_part_scene()
    table = LayerTable.from_parts(scene.parts, scene.material_ids)
    x, part, gid = fill_layers(scene.parts, table, np.arange(len(table.z)))
    assert np.array_equal(gid, np.arange(table.n_points))
    mat = np.array([scene.material_ids[p.material] for p in scene.parts])[part]
    keys = np.lexsort((x[:, 0], x[:, 1], mat, x[:, 2]))
    assert np.array_equal(keys, np.arange(len(gid)))


def test_slabs_balanced_and_contiguous():
    scene = two_part_scene()
    table = LayerTable.from_parts(scene.parts, scene.material_ids)
    slabs = decompose(table, 3, halo_width(scene))
    owned = [slabs.points_of(r)[0] for r in range(3)]
    assert sum(owned) == table.n_points
    assert max(owned) - min(owned) <= table.count.max() * 2      # whole z levels
    ranges = [slabs.gid_range(r) for r in range(3)]
    assert ranges[0][0] == 0 and ranges[-1][1] == table.n_points
    assert all(ranges[r][1] == ranges[r + 1][0] for r in range(2))
    # a z level is never split between ranks
    for r in range(2):
        a, b = slabs.owned(r)
        assert table.z[b - 1] < table.z[b]


def test_ghosts_cover_every_family_and_no_rank_holds_everything():
    scene = two_part_scene()
    table = LayerTable.from_parts(scene.parts, scene.material_ids)
    slabs = decompose(table, 3, halo_width(scene))
    full_x, _, _ = fill_layers(scene.parts, table, np.arange(len(table.z)))
    full_gid = np.arange(table.n_points)
    horizon = np.full(table.n_points, scene.parts[0].horizon)
    ref = build_families(full_x, full_gid, horizon, table.n_points)
    for r in range(3):
        p = local_points(scene, slabs, r)
        assert p.n_local < table.n_points
        fam = build_families(p.x, p.gid, p.horizon, p.n_owned)
        g0, _ = slabs.gid_range(r)
        for i in range(0, p.n_owned, 37):
            mine = p.gid[fam.nbr[fam.offsets[i]:fam.offsets[i + 1]]]
            gi = p.gid[i]
            want = full_gid[ref.nbr[ref.offsets[gi]:ref.offsets[gi + 1]]]
            assert np.array_equal(mine, want)          # same family, same gid order
            assert np.all(np.diff(mine) > 0)
            assert gi - g0 == i


def test_halo_plans_match_between_ranks():
    scene = two_part_scene()
    table = LayerTable.from_parts(scene.parts, scene.material_ids)
    for n in (2, 3, 5):
        slabs = decompose(table, n, halo_width(scene))
        plans = [slabs.plan(r) for r in range(n)]
        pts = [local_points(scene, slabs, r) for r in range(n)]
        for r in range(n):
            for q, a, b in plans[r][0]:                      # r receives [a, b) from q
                sends = [(s0, s1) for (dst, s0, s1) in plans[q][1] if dst == r]
                assert len(sends) == 1
                s0, s1 = sends[0]
                assert np.array_equal(pts[r].gid[a:b], pts[q].gid[s0:s1])


def test_too_many_ranks_refused():
    scene = make_scene(scene_dict({"kind": "box", "lo": [0, 0, 0], "hi": [0.01, 0.01, 0.003]}))
    table = LayerTable.from_parts(scene.parts, scene.material_ids)
    with pytest.raises(DecompositionError, match="3 z levels"):
        decompose(table, 4, halo_width(scene))


def test_the_gas_is_on_every_rank_and_the_solids_only_in_their_slabs():
    """detonation_tube: the charge is held whole on every rank; the copper it acts on
    (interacts_with) and the rock, only within the halo (a gas point's solids beyond
    it come as remote rows, mpipd.parallel.near); ``holds`` says exactly which
    layers a rank has."""
    from mpipd.input import scene as sc
    from mpipd.parallel.decomp import replicated_parts
    scene, _ = sc.load("detonation_tube")
    names = [q.name for q in scene.parts]
    assert [names[k] for k in replicated_parts(scene)] == ["charge"]
    table = LayerTable.from_parts(scene.parts, scene.material_ids)
    slabs = decompose(table, 3, halo_width(scene), replicated_parts(scene))
    every = np.arange(len(table.z))
    for r in range(3):
        p = local_points(scene, slabs, r)
        assert np.sum(p.part == 0) == table.count[table.part == 0].sum()
        z0, z1 = slabs.z_range(r)
        for k in (1, 2):
            solid = p.part == k
            assert solid.sum() < table.count[table.part == k].sum()
            assert np.all((p.x[solid, 2] > z0 - slabs.halo) & (p.x[solid, 2] < z1 + slabs.halo))
        held = np.unique(slabs.layer_of(p.gid))
        assert np.array_equal(every[slabs.holds(r, every)], held)
        assert np.array_equal(slabs.owner_of_gid(p.gid[:p.n_owned]),
                              np.full(p.n_owned, r))
