"""mpipd.kernels.index: the masked family range and neighbour index read exactly what
plain indexing reads, for every index a model can hold."""
import numba
import numpy as np

from mpipd.kernels.index import family, neighbour


@numba.njit
def _spans(offsets, nbr):
    out = np.empty((offsets.shape[0] - 1, 2), np.int64)
    js = np.empty(nbr.shape[0], np.int64)
    for i in range(offsets.shape[0] - 1):
        out[i, 0], out[i, 1] = family(offsets, i)
    for b in range(nbr.shape[0]):
        js[b] = neighbour(nbr, b)
    return out, js


def test_the_masks_change_no_valid_index():
    offsets = np.array([0, 3, 3, 2**40, 2**62 - 1], np.int64)
    nbr = np.array([0, 1, 2**20, 2**31 - 1], np.int32)
    spans, js = _spans(offsets, nbr)
    np.testing.assert_array_equal(spans[:, 0], offsets[:-1])
    np.testing.assert_array_equal(spans[:, 1], offsets[1:])
    np.testing.assert_array_equal(js, nbr)


@numba.njit
def _sum_both_ways(offsets, nbr, a):
    s1 = s2 = 0.0
    for i in range(offsets.shape[0] - 1):
        for b in range(offsets[i], offsets[i + 1]):
            s1 += a[nbr[b]] * (b + 1)
        for b in range(*family(offsets, i)):
            s2 += a[neighbour(nbr, b)] * (b + 1)
    return s1, s2


def test_a_bond_loop_reads_the_same_bonds_and_neighbours():
    rng = np.random.default_rng(3)
    counts = rng.integers(0, 9, 50)
    offsets = np.concatenate(([0], np.cumsum(counts))).astype(np.int64)
    nbr = rng.integers(0, 50, offsets[-1]).astype(np.int32)
    s1, s2 = _sum_both_ways(offsets, nbr, rng.random(50))
    assert s1 == s2
