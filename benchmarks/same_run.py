"""Are two run files the same run, bit for bit?  (issue 16: refactors keep results)

    python benchmarks/same_run.py A/run.h5 B/run.h5

Compares every dataset under /geometry, /fields, /time, /energy and /probes
byte for byte (NaN = NaN), and every root and dataset attribute except the
provenance ones (git_commit, run_id, segments, mpipd_version, ranks).  Prints
one line per difference and exits 1 if there is any, 0 otherwise.
"""
import sys

import h5py
import numpy as np

PROVENANCE = {"git_commit", "run_id", "segments", "mpipd_version", "ranks"}


def _same(a, b) -> bool:
    a, b = np.asarray(a), np.asarray(b)
    if a.shape != b.shape or a.dtype != b.dtype:
        return False
    if a.dtype.kind in "fc":
        return a.tobytes() == b.tobytes() or bool(np.array_equal(a, b, equal_nan=True))
    return bool(np.array_equal(a, b))


def compare(path_a, path_b) -> list[str]:
    out = []
    with h5py.File(path_a, "r") as fa, h5py.File(path_b, "r") as fb:
        for k in sorted(set(fa.attrs) | set(fb.attrs)):
            if k in PROVENANCE:
                continue
            if k not in fa.attrs or k not in fb.attrs:
                out.append(f"attr {k}: only in {'B' if k not in fa.attrs else 'A'}")
            elif not _same(fa.attrs[k], fb.attrs[k]):
                out.append(f"attr {k}: differs")
        names_a, names_b = [], []
        fa.visititems(lambda n, o: names_a.append(n) if isinstance(o, h5py.Dataset) else None)
        fb.visititems(lambda n, o: names_b.append(n) if isinstance(o, h5py.Dataset) else None)
        for n in sorted(set(names_a) | set(names_b)):
            if n not in names_a or n not in names_b:
                out.append(f"{n}: only in {'B' if n not in names_a else 'A'}")
                continue
            da, db = fa[n], fb[n]
            if not _same(da[()], db[()]):
                x, y = np.asarray(da[()], float), np.asarray(db[()], float)
                msg = ""
                if x.shape == y.shape:
                    d = np.abs(x - y)
                    msg = f" (max |A - B| {np.nanmax(d):.3e} in {int(np.sum(d > 0))} values)"
                out.append(f"{n}: differs{msg}")
            for k in sorted(set(da.attrs) | set(db.attrs)):
                if k in PROVENANCE:
                    continue
                if k not in da.attrs or k not in db.attrs or not _same(da.attrs[k], db.attrs[k]):
                    out.append(f"{n} attr {k}: differs")
    return out


def main(argv=None) -> int:
    args = sys.argv[1:] if argv is None else argv
    if len(args) != 2:
        print(__doc__.strip().splitlines()[2].strip(), file=sys.stderr)
        return 2
    diffs = compare(*args)
    for d in diffs:
        print(d)
    print(f"{args[0]} and {args[1]}: " + ("the same run, bit for bit" if not diffs
                                          else f"{len(diffs)} difference(s)"))
    return 1 if diffs else 0


if __name__ == "__main__":
    sys.exit(main())
