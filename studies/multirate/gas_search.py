"""Time the gas's pair search (mpipd.model.gas.Gas._pairs) on a saved frame of a run
file, every point in this one process (a one-rank view of the run), and optionally
against the search of another commit, interleaved, checking that both give the same
pairs.

    python studies/multirate/gas_search.py runs/blast_paper_kappa/run.h5 --frame 9 --against 5a6162e

``--against`` takes that commit's kernels/search.py (``git show``) and its ``_pairs``
rule: every eligible solid in the gas's bounding box a candidate (the rule before
1c225d0).  The gas is material 0 with the horizon ``--horizon``; the skin is the
model's (mpipd.model.gas.SKIN).
"""
from __future__ import annotations

import argparse
import importlib.util
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from types import SimpleNamespace

import h5py
import numpy as np

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))


def search_module_of(commit: str):
    """kernels/search.py of ``commit``, imported under another name."""
    src = subprocess.run(["git", "-C", str(ROOT), "show", f"{commit}:mpipd/kernels/search.py"],
                         check=True, capture_output=True, text=True).stdout
    path = Path(tempfile.mkdtemp()) / f"search_{commit}.py"
    path.write_text(src)
    spec = importlib.util.spec_from_file_location(path.stem, path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def box_rule(old):
    """The pair search before 1c225d0, with ``old``'s kernels."""
    def pairs(self, ye, n):
        cell = self.reach + self.skin
        yg = ye[self.gas_all]
        lo, hi = yg.min(axis=0) - cell, yg.max(axis=0) + cell

        def in_box(idx):
            return idx[np.all((ye[idx] >= lo) & (ye[idx] <= hi), axis=1)]
        el = in_box(self.el_ext)
        lo_el, dims = old.cell_counts(ye[el], cell)
        ca, na = old.cell_pairs(ye, self.gas_idx, el, self.h_ext, self.skin, cell, lo_el, dims,
                                self.gid_ext, n)
        lo_g, dims = old.cell_counts(yg, cell)
        cb, nb = old.cell_pairs(ye, in_box(self.solids_owned), self.gas_all, self.h_ext,
                                self.skin, cell, lo_g, dims, self.gid_ext, n)
        counts, self.nbr = old.merge_rows(ca, na, cb, nb)
        self.offsets[1:] = np.cumsum(counts)
    return pairs


def main(argv=None) -> int:
    from mpipd.model.gas import SKIN, Gas
    ap = argparse.ArgumentParser()
    ap.add_argument("run")
    ap.add_argument("--frame", type=int, default=-1)
    ap.add_argument("--horizon", type=float, default=1.5e-3, help="the gas horizon (m)")
    ap.add_argument("--against", help="a commit whose search to time beside this one")
    ap.add_argument("--repeat", type=int, default=4)
    args = ap.parse_args(argv)
    with h5py.File(args.run, "r") as f:
        x = f["geometry/x"][:]
        mat = f["geometry/material"][:]
        y = x + f["fields/u"][args.frame]
        t = float(f["time"][args.frame])
    n = len(y)
    is_gas = (mat == 0).astype(np.uint8)
    gas = np.flatnonzero(is_gas).astype(np.int64)
    everyone = np.arange(n, dtype=np.int64)
    g = SimpleNamespace(rows=everyone, el_ext=everyone, reach=args.horizon, skin=SKIN * args.horizon,
                        h_ext=np.where(is_gas > 0, args.horizon, 0.0), gid_ext=everyone,
                        isgas_ext=is_gas, gas_all=gas, gas_idx=gas,
                        solids_owned=np.flatnonzero(is_gas == 0), offsets=np.zeros(n + 1, np.int64))
    rules = {"this": Gas._pairs}
    if args.against:
        rules[args.against] = box_rule(search_module_of(args.against))
    result, times = {}, {k: [] for k in rules}
    for name, rule in rules.items():                 # compile
        rule(g, y, n)
    for _ in range(args.repeat):
        for name, rule in rules.items():
            t0 = time.perf_counter()
            rule(g, y, n)
            times[name].append(time.perf_counter() - t0)
            result[name] = (g.offsets.copy(), g.nbr.copy())
    same = all(np.array_equal(a[0], result["this"][0]) and np.array_equal(a[1], result["this"][1])
               for a in result.values())
    span = (y[gas].max(axis=0) - y[gas].min(axis=0)) * 1e3
    print(f"gas search, {args.run} frame {args.frame} (t = {t * 1e6:.1f} us): {n} points, "
          f"{len(gas)} gas over {span[0]:.0f} x {span[1]:.0f} x {span[2]:.0f} mm, "
          f"{result['this'][0][-1]} pairs")
    for name in rules:
        print(f"  {name}: {np.median(times[name]):.3f} s (median of {args.repeat})")
    if args.against:
        print(f"  ratio {np.median(times[args.against]) / np.median(times['this']):.1f}; "
              f"same pairs: {same}")
    return 0 if same else 1


if __name__ == "__main__":
    sys.exit(main())
