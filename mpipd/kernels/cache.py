"""Where numba keeps the compiled kernels: one directory per version of the sources.

numba's ``cache=True`` re-checks only the file that defines a function.  A kernel
that calls a function of another module (and inlines it: ``classes.weight`` in
``nosb.gather_forces``, ``linalg`` everywhere) keeps its cached machine code after
that other module changes; numba documents this among its cache's limitations
(numba issue #1833).  A run of changed code could then compute with the old
kernels and say nothing.

So :func:`configure` (called by ``import mpipd``, before any kernel is defined)
points numba at ``<root>/<key>``, the key a hash of every ``.py`` source of mpipd
and of ``postprocess`` beside it (names and contents): any change to any source
starts a fresh cache.  Clones of the same sources share the key's directory but
not the machine code (numba names its subdirectories by each source's absolute
path).  The root is ``$MPIPD_KERNEL_CACHE``, else ``$NUMBA_CACHE_DIR``, else
``$XDG_CACHE_HOME/mpipd/numba`` (``~/.cache/mpipd/numba``).  Directories of other
keys (16 hex digits) unused for ``KEEP_DAYS`` are removed; an import marks its
key's directory used.  If the root cannot be made, numba's own locators take over
(the cache beside the sources) and a warning says so.

The ids numba puts in every compiled function's symbol (``v<id>``) are drawn at random
(:func:`random_function_ids`) instead of counted from 1 in each process.  With counted
ids, two processes give different bodies the same symbol (the same helper, say a
``quicksort`` closure, the same id, other closure variables); a later process that
loads both cached libraries binds one body for both and calls the wrong one.  That
crashed ``test_gas.py`` on 2026-12-04 with a cached ``search.near_cells`` compiled as
its process's first function (numba issue #10486, where this remedy is proposed).
"""
from __future__ import annotations

import hashlib
import os
import secrets
import shutil
import time
import warnings
from pathlib import Path

#: the packages (beside each other) whose sources key the cache
PACKAGES = ("mpipd", "postprocess")
#: a key's directory unused for this many days is removed
KEEP_DAYS = 14
HEX = set("0123456789abcdef")


def source_key(roots) -> str:
    """Hash of the ``.py`` files under ``roots`` (their paths relative to each root's
    parent, and their bytes), 16 hex digits."""
    h = hashlib.sha256()
    for root in roots:
        root = Path(root)
        for p in sorted(root.rglob("*.py")):
            if p.name.startswith(".") or not p.is_file():    # an editor's lock file
                continue
            h.update(p.relative_to(root.parent).as_posix().encode())
            h.update(b"\0")
            h.update(p.read_bytes())
            h.update(b"\0")
    return h.hexdigest()[:16]


def cache_root() -> Path:
    """The directory the keyed caches live in (module docstring)."""
    for var in ("MPIPD_KERNEL_CACHE", "NUMBA_CACHE_DIR"):
        if os.environ.get(var):
            return Path(os.environ[var])
    base = os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache"
    return Path(base) / "mpipd" / "numba"


def _prune(root: Path, keep: str) -> None:
    """Remove the keyed directories other than ``keep`` unused for KEEP_DAYS."""
    old = time.time() - KEEP_DAYS * 86400.0
    for d in root.iterdir():
        if d.name == keep or len(d.name) != 16 or any(c not in HEX for c in d.name):
            continue
        try:                                  # another rank may be removing it too
            if d.is_dir() and d.stat().st_mtime < old:
                shutil.rmtree(d, ignore_errors=True)
        except OSError:
            pass


class _RandomIds:
    """An endless iterator of random 63-bit integers (numba draws function ids with next())."""

    def __iter__(self):
        return self

    def __next__(self) -> int:
        return secrets.randbits(63)


def random_function_ids() -> None:
    """Make numba's function ids random in this process (module docstring)."""
    from numba.core import bytecode

    if not isinstance(bytecode.FunctionIdentity._unique_ids, _RandomIds):
        bytecode.FunctionIdentity._unique_ids = _RandomIds()


def configure() -> Path | None:
    """Point numba's cache at ``cache_root()/source_key(...)``; returns that directory
    (None, with a warning, if it cannot be made)."""
    import numba

    random_function_ids()
    here = Path(__file__).resolve().parents[1]            # the mpipd package
    roots = [here.parent / name for name in PACKAGES if (here.parent / name).is_dir()]
    try:
        key = source_key(roots)
        root = cache_root()
        path = root / key
        path.mkdir(parents=True, exist_ok=True)
        os.utime(path)                                   # in use: not pruned
    except (OSError, RuntimeError) as e:                 # RuntimeError: no home directory
        warnings.warn(f"mpipd: no keyed kernel cache ({e}); numba caches beside the "
                      "sources, which miss changes across modules", stacklevel=2)
        return None
    numba.config.CACHE_DIR = str(path)
    try:
        _prune(root, key)
    except OSError:
        pass
    return path
