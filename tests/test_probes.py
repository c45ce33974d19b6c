"""Probes name the material they sample: ``part`` restricts the snap to that part and
its zones, an unknown part is a one-line scene error, and the built-in blast scenes'
probes all sample the rock."""
import numpy as np
import pytest
from conftest import granite, make_scene, scene_dict

from mpipd.input import scene as sc
from mpipd.input.probes import part_matches
from mpipd.input.schema import SceneError
from mpipd.solver import Simulation

L = 0.0048


def rock_beside_copper(probes):
    """Rock (0.8 mm) for x < 8 mm, copper (0.3 mm) from 8 to 9.2 mm."""
    d = scene_dict(None, parts=[
        {"name": "rock", "material": "rock", "dx": 0.8e-3,
         "shape": {"kind": "box", "lo": [0, 0, 0], "hi": [0.008, L, L]}},
        {"name": "tube", "material": "copper", "dx": 0.3e-3, "horizon_factor": 1.0 / 0.3,
         "shape": {"kind": "box", "lo": [0.008, 0, 0], "hi": [0.0092, L, L]}}])
    d["materials"] = {"rock": granite(),
                      "copper": granite(bulk_modulus=130e9, shear_modulus=45e9, density=8960.0)}
    d["probes"] = probes
    return d


def test_part_names_match_their_zones():
    assert part_matches("rock", "rock") and part_matches("rock", "rock.band")
    assert part_matches("rock", "rock.3") and part_matches("rock.band", "rock.band")
    assert not part_matches("rock", "rocky") and not part_matches("rock", "tube")


def test_unknown_part_is_a_one_line_scene_error():
    d = rock_beside_copper([{"name": "A", "position": [0.004, 0.002, 0.002]},
                            {"name": "B", "position": [0.004, 0.002, 0.002], "part": "granit"}])
    with pytest.raises(SceneError) as e:
        make_scene(d)
    msg = str(e.value)
    assert msg.startswith("probes.1.part: no part 'granit'") and "\n" not in msg
    assert "rock" in msg and "tube" in msg


def test_probe_snaps_to_the_nearest_point_of_its_part(team):
    """A position inside the copper: without ``part`` the nearest point is copper; with
    ``part = "rock"`` it is the nearest rock point (found here by brute force)."""
    pos = [0.0083, 0.0021, 0.0021]
    scene = make_scene(rock_beside_copper([
        {"name": "free", "position": pos},
        {"name": "wall", "position": pos, "part": "rock"}]))
    sim = Simulation(scene, team)
    p, pr = sim.points, sim.probes
    n = p.n_owned
    dist = np.linalg.norm(p.x[:n] - np.asarray(pos), axis=1)
    rock = p.part[:n] == 0

    def nearest(mask):
        d = np.where(mask, dist, np.inf)
        best = d.min()
        return int(p.gid[:n][d == best].min()), best       # lowest gid on a tie
    g_any, d_any = nearest(np.ones(n, bool))
    g_rock, d_rock = nearest(rock)
    assert pr.gid == [g_any, g_rock]
    assert pr.part == ["tube", "rock"] and pr.material == ["copper", "rock"]
    assert pr.dist == pytest.approx([d_any, d_rock], rel=1e-12)
    assert d_rock > d_any and p.part[np.flatnonzero(p.gid[:n] == g_rock)[0]] == 0


@pytest.mark.parametrize("name", ["blast_demo", "blast_paper", "blast_slice"])
def test_builtin_blast_probes_sample_the_rock(name):
    scene, _ = sc.load(name)
    assert scene.probes and all(pr.part == "rock" for pr in scene.probes)
    assert "wall" in [pr.name for pr in scene.probes]
    for case in sc.cases(name):         # the scene check passes with zones (band, grade) too
        s, _ = sc.load(f"{name}:{case}")
        assert all(pr.part == "rock" for pr in s.probes)
        assert any(q.name != "rock" and part_matches("rock", q.name) for q in s.parts) \
            or all(q.name in ("charge", "tube", "rock") for q in s.parts)


def test_blast_paper_slab_keeps_every_probe_inside_its_cut():
    """blast_paper:slab (the integration's test bed, make multirate-slab) is the scene
    cut to z <= 10 mm and r <= 40 mm: it keeps every probe of the scene that lies in
    the cut, at the same place, and no other."""
    base, _ = sc.load("blast_paper")
    slab, _ = sc.load("blast_paper:slab")
    rock = slab.parts[2].shape
    assert (rock.radius, tuple(rock.z)) == (0.040, (0.0, 0.010))
    assert all(tuple(p.shape.z) == (0.0, 0.010) for p in slab.parts)
    assert [p.shape.radius for p in slab.parts[:2]] == [p.shape.radius for p in base.parts[:2]]

    def inside(pr):
        r = float(np.hypot(pr.position[0], pr.position[1]))
        return rock.inner_radius < r < rock.radius and rock.z[0] < pr.position[2] < rock.z[1]
    kept = {pr.name: tuple(pr.position) for pr in base.probes if inside(pr)}
    assert {pr.name: tuple(pr.position) for pr in slab.probes} == kept
    assert set(kept) == {"wall", "A", "B", "C", "D", "P1", "P2", "P3"}
