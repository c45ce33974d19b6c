"""The indices a bond loop reads its arrays with.

numba gives a signed index Python's meaning: ``a[k]`` with ``k < 0`` reads
``a[len(a) + k]``.  Every access through a signed integer therefore compiles to a
sign test and a select, with the array's length held in a register or reloaded,
and in a bond loop that reads eight arrays at the neighbour's index this is more
integer work than the loop's arithmetic, and it pushes the loop's floating-point
values out of registers.  The families' indices are never negative
(mpipd.model.families: ``offsets`` int64 from 0, ``nbr`` int32 local indices),
but the compiler cannot know it.  Clearing the sign bit tells it: the mask leaves
every valid index as it is, and LLVM drops the wraparound from each access made
through the index, and through the loop variable of ``range(first, end)`` once
``first`` is masked.

A bond loop is written

    for b in range(*family(offsets, i)):
        j = neighbour(nbr, b)

and computes exactly what ``range(offsets[i], offsets[i + 1])`` and ``nbr[b]``
would, bit for bit (README, "Indices the compiler knows are not negative", has the
measured change).
"""
import numba

#: clears an int64's sign bit (offsets stay below 2^62)
_BOND = (1 << 62) - 1
#: clears an int32's sign bit (local indices stay below 2^31)
_POINT = (1 << 31) - 1


@numba.njit(cache=True, inline="always")
def family(offsets, i):
    """(first, end) of point i's bonds in the CSR arrays, non-negative to the compiler."""
    return offsets[i] & _BOND, offsets[i + 1] & _BOND


@numba.njit(cache=True, inline="always")
def neighbour(nbr, b):
    """The local index of bond b's other point, non-negative to the compiler."""
    return nbr[b] & _POINT
