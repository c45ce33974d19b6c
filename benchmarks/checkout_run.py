"""Run mpipd from another checkout with this interpreter (A/B benches, bit-for-bit
comparisons of two commits):

    python benchmarks/checkout_run.py CHECKOUT -m mpipd.cli run SCENE ...
    python benchmarks/checkout_run.py CHECKOUT path/to/script.py ARGS ...

The project's editable install puts a finder on ``sys.meta_path`` that maps
``mpipd`` to the installed work tree ahead of ``PYTHONPATH``, so setting
PYTHONPATH alone would run the installed tree.  This drops that finder and puts
CHECKOUT first on ``sys.path`` before running the module or script.
"""
import runpy
import sys
from pathlib import Path


def use_checkout(root: Path) -> None:
    sys.meta_path[:] = [f for f in sys.meta_path
                        if not getattr(f, "__module__", "").startswith("__editable__")]
    sys.path.insert(0, str(root))


def main() -> None:
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    root = Path(sys.argv[1]).resolve()
    use_checkout(root)
    if sys.argv[2] == "-m":
        sys.argv = [sys.argv[3]] + sys.argv[4:]
        runpy.run_module(sys.argv[0], run_name="__main__", alter_sys=True)
    else:
        sys.argv = sys.argv[2:]
        runpy.run_path(sys.argv[0], run_name="__main__")


if __name__ == "__main__":
    main()
