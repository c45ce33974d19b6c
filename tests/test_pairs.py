"""Broken bonds as gid pairs: Families.broken_pairs / set_broken (the checkpoint's and
the fragment analysis's round trip) and the bisection that finds a rank's rows on
disk (mpipd.output.pairs), against direct set arithmetic computed in the test."""
import h5py
import numpy as np
import pytest

from mpipd.model.families import build_families
from mpipd.output.pairs import rows_between


@pytest.fixture
def fam_and_gid():
    rng = np.random.default_rng(7)
    x = rng.random((400, 3))
    gid = rng.permutation(10_000)[:400].astype(np.int64)     # sparse, unordered gids
    fam = build_families(x, gid, np.full(400, 0.18), 300)     # 300 owned, 100 ghosts
    return fam, gid


def _bond_set(fam, gid, mask):
    rows = np.repeat(np.arange(len(fam.offsets) - 1), np.diff(fam.offsets))
    return {(int(gid[i]), int(gid[j])) for i, j, m in zip(rows, fam.nbr, mask) if m}


def test_directed_pairs_round_trip(fam_and_gid):
    fam, gid = fam_and_gid
    want = np.random.default_rng(1).random(fam.n_bonds) < 0.3
    fam.broken[:] = want
    pairs = fam.broken_pairs(gid)
    assert {tuple(p) for p in pairs.tolist()} == _bond_set(fam, gid, want)
    fam.broken[:] = 1                                    # set_broken clears first
    assert fam.set_broken(gid, pairs) == 0
    assert np.array_equal(fam.broken.astype(bool), want)


def test_lower_pairs_marked_both_ways(fam_and_gid):
    fam, gid = fam_and_gid
    # a symmetric breakage: a bond is broken in both owned copies or in none
    rows = np.repeat(np.arange(300), np.diff(fam.offsets))
    key = np.minimum(gid[rows], gid[fam.nbr]) * 7 + np.maximum(gid[rows], gid[fam.nbr]) * 3
    want = key % 5 == 0
    fam.broken[:] = want
    lower = fam.broken_pairs(gid, lower=True)
    assert np.all(lower[:, 0] < lower[:, 1])
    # a ghost's lower copy (ghost gid < owned gid) is not held here: add those pairs,
    # as a reader of the run file gets them from the rank that owns the lower end
    extra = np.array([(int(gid[j]), int(gid[i])) for i, j, m in zip(rows, fam.nbr, want)
                      if m and j >= 300 and gid[j] < gid[i]], np.int64).reshape(-1, 2)
    fam.broken[:] = 0
    assert fam.set_broken(gid, np.concatenate([lower, extra]), both=True) == 0
    assert np.array_equal(fam.broken.astype(bool), want)


def test_pairs_that_are_not_bonds_are_counted(fam_and_gid):
    fam, gid = fam_and_gid
    i = 0
    far = [g for g in gid[300:].tolist() + [20_000]
           if g not in set(gid[fam.nbr[fam.offsets[i]:fam.offsets[i + 1]]].tolist())][0]
    pairs = np.array([[gid[i], far], [30_000, gid[0]]], np.int64)   # a miss; no owned end
    assert fam.set_broken(gid, pairs) == 1
    assert not fam.broken.any()


def test_rows_between_is_searchsorted_on_disk(tmp_path):
    rng = np.random.default_rng(3)
    col = np.sort(rng.integers(0, 50, 300))
    data = np.stack([col, rng.integers(0, 99, 300)], axis=1)
    with h5py.File(tmp_path / "p.h5", "w") as f:
        d = f.create_dataset("b", data=data)
        for a, b in [(0, 300), (40, 260), (0, 0), (120, 121)]:
            for lo, hi in [(0, 50), (10, 11), (13, 31), (49, 60), (-5, 0), (60, 70)]:
                seg = col[a:b]
                s, e = np.searchsorted(seg, lo), np.searchsorted(seg, hi)
                got = rows_between(d, a, b, lo, hi)
                assert got.dtype == np.int64 and got.shape == (e - s, 2)
                assert np.array_equal(got, data[a + s:a + e])
