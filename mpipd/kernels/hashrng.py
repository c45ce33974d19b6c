"""Counter-based random numbers keyed by (seed, stream, global id).

A per-point random value must not depend on which rank holds the point or on
the order points are visited, so it is a pure function of the point's global id:

    h = mix(mix(seed * 2^16 + stream) + gid),   u = (h >> 11 + 1/2) / 2^53  in (0, 1)

with ``mix`` the SplitMix64 finaliser (Steele, Lea & Flood 2014, "Fast splittable
pseudorandom number generators", OOPSLA; the constants are Stafford's "Mix13").
Consecutive keys give statistically independent outputs (SplitMix64 passes
BigCrush on a counter), which is what a field over gids needs.  ``stream``
separates the uses (a heterogeneity field, each jitter axis, joint patches), so
one seed does not correlate them.

Setup-time only: the fields are drawn once when a model is built.
"""
from __future__ import annotations

import numba
import numpy as np

#: streams of the uses (one each, so a seed never correlates two of them)
STREAM_STRENGTH = 1
STREAM_JITTER = 2          # and 3, 4: one per axis
STREAM_JOINT = 5


@numba.njit(cache=True, inline="always")
def _mix(z):
    z = (z ^ (z >> np.uint64(30))) * np.uint64(0xBF58476D1CE4E5B9)
    z = (z ^ (z >> np.uint64(27))) * np.uint64(0x94D049BB133111EB)
    return z ^ (z >> np.uint64(31))


@numba.njit(cache=True)
def _uniform(seed, stream, keys, out):
    golden = np.uint64(0x9E3779B97F4A7C15)
    base = _mix(np.uint64(seed) * np.uint64(65536) + np.uint64(stream) + golden)
    for k in range(keys.shape[0]):
        h = _mix(base + np.uint64(keys[k]) * golden)
        out[k] = ((h >> np.uint64(11)) + 0.5) * (1.0 / 9007199254740992.0)


def uniform(seed: int, stream: int, keys) -> np.ndarray:
    """One number in (0, 1) per key (a global id, or any non-negative integer key)."""
    keys = np.ascontiguousarray(keys, dtype=np.int64)
    if keys.size and keys.min() < 0:
        raise ValueError("hashrng keys must be non-negative")
    out = np.empty(keys.shape[0], np.float64)
    _uniform(np.int64(seed), np.int64(stream), keys, out)
    return out


@numba.njit(cache=True)
def _row_sum(words, keys, salt):
    golden = np.uint64(0x9E3779B97F4A7C15)
    total = np.uint64(0)
    for r in range(words.shape[0]):
        base = _mix(np.uint64(salt) + np.uint64(keys[r]) * golden)
        for c in range(words.shape[1]):
            total += _mix(words[r, c] ^ _mix(base + np.uint64(c + 1) * golden))
    return total


def row_checksum(arr, keys, salt: int) -> int:
    """A checksum of the rows of ``arr`` (any dtype; row r keyed by ``keys[r]``, e.g. its
    gid): the sum mod 2^64 over the rows and their 8-byte words of mix(word ^
    mix(mix(salt + key golden) + column golden)).  A sum, so the checksum of a whole
    dataset is the sum (mod 2^64) of its pieces', however the rows are split among
    ranks or ordered; any changed word, or a row moved to another key, changes it
    (except with probability about 2^-64).  mpipd.output.checkpoint."""
    a = np.ascontiguousarray(arr)
    n = a.shape[0]
    raw = a.reshape(n, -1).view(np.uint8).reshape(n, -1) if n else np.empty((0, 8), np.uint8)
    width = -(-raw.shape[1] // 8) * 8
    if width != raw.shape[1]:
        padded = np.zeros((n, width), np.uint8)
        padded[:, :raw.shape[1]] = raw
        raw = padded
    words = np.ascontiguousarray(raw).view(np.uint64)
    keys = np.ascontiguousarray(keys, dtype=np.int64)
    return int(_row_sum(words, keys, np.uint64(salt % 2 ** 64)))
