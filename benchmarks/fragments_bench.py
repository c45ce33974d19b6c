"""Fragment analysis time against point count, on 1 and 2 ranks (issue 19's bench;
``make bench`` runs it after the solver cases).

    python benchmarks/fragments_bench.py [--sizes 100000,1000000] [--ranks 1,2]

For each size: an elastic granite cube of about that many points at dx = 1 mm, cut
by three sets of joints 7 mm apart (x, y and z planes: blocks of 7^3 points), is
written at step 0 (``mpipd run``, steps = 0: the broken bonds are the joints', a
synthetic fracture field with a known answer), then ``python -m mpipd.post
fragments`` runs on each rank count.  Printed: the command's wall time (start-up,
rebuilding the families from the scene, labelling, statistics, files) and the
fragment count, which must be the same on every rank count.
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
from pathlib import Path

BIN = Path(sys.executable).parent
SCENE = """
[scene]
name = "fragments_bench"
[time]
dt = 1.0e-7
steps = 0
[materials.granite]
model = "elastic"
density = 2660.0
bulk_modulus = 21.9e9
shear_modulus = 25.7e9
[[parts]]
name = "block"
material = "granite"
dx = 1.0e-3
shape = {{ kind = "box", lo = [0.0, 0.0, 0.0], hi = [{L}, {L}, {L}] }}
[solver]
contact = true
[[joints]]
point = [0.0005, 0.0005, 0.0005]
normal = [1.0, 0.0, 0.0]
spacing = 0.007
[[joints]]
point = [0.0005, 0.0005, 0.0005]
normal = [0.0, 1.0, 0.0]
spacing = 0.007
[[joints]]
point = [0.0005, 0.0005, 0.0005]
normal = [0.0, 0.0, 1.0]
spacing = 0.007
[output]
every = 1
fields = ["u"]
"""


def main(argv=None):
    ap = argparse.ArgumentParser()
    ap.add_argument("--sizes", default="100000,1000000")
    ap.add_argument("--ranks", default="1,2")
    ap.add_argument("--out", default="runs/fragments_bench")
    args = ap.parse_args(argv)
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
               OMP_NUM_THREADS="1")
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    for size in map(int, args.sizes.split(",")):
        n = round(size ** (1 / 3))
        d = out / f"n{n ** 3}"
        d.mkdir(exist_ok=True)
        (d / "scene.toml").write_text(SCENE.format(L=n * 1e-3))
        subprocess.run(["mpirun", "--oversubscribe", "-n", "2", str(BIN / "mpipd"), "run",
                        str(d / "scene.toml"), "--out", str(d / "run"), "--overwrite",
                        "--quiet"], env=env, check=True)
        counts = set()
        for ranks in map(int, args.ranks.split(",")):
            t0 = time.perf_counter()
            subprocess.run(["mpirun", "--oversubscribe", "-n", str(ranks), sys.executable, "-m",
                            "mpipd.post", "fragments", str(d / "run" / "run.h5"), "--out",
                            str(d / f"frag{ranks}")], env=env, check=True,
                           stdout=subprocess.DEVNULL)
            wall = time.perf_counter() - t0
            doc = json.loads((d / f"frag{ranks}" / "fragments.json").read_text())
            counts.add(doc["fragments"])
            print(f"fragments {n ** 3:>9d} points  {ranks} rank(s)  {wall:7.1f} s  "
                  f"{doc['fragments']} fragments  {n ** 3 / wall / 1e3:8.1f} k points/s",
                  flush=True)
        if len(counts) != 1:
            print(f"fragments: the count differs between rank counts: {sorted(counts)}")
            return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
