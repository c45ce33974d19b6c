"""The kernel cache is keyed by the sources (mpipd.kernels.cache): a change in any
module gives a new cache directory, so no kernel runs with machine code inlined
from an older version of another module."""
import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

import numba

import mpipd
from mpipd.kernels import cache

REPO = Path(mpipd.__file__).resolve().parents[1]


def _tree(tmp_path, name):
    """A copy of the mpipd package's sources (no caches) under tmp_path/name."""
    dst = tmp_path / name / "mpipd"
    shutil.copytree(REPO / "mpipd", dst, ignore=shutil.ignore_patterns("__pycache__"))
    return dst


def test_the_key_follows_every_source_and_only_the_sources(tmp_path):
    a, b = _tree(tmp_path, "a"), _tree(tmp_path, "b")
    key = cache.source_key([a])
    assert key == cache.source_key([b])                 # same sources, another place
    (b / "kernels" / "__pycache__").mkdir(exist_ok=True)
    (b / "kernels" / "__pycache__" / "x.nbi").write_bytes(b"not a source")
    assert cache.source_key([b]) == key
    f = b / "kernels" / "classes.py"                    # inlined into nosb.gather_forces
    f.write_text(f.read_text() + "\n# one more line\n")
    assert cache.source_key([b]) != key
    g = a / "kernels" / "linalg.py"                     # a rename changes the key too
    g.rename(a / "kernels" / "linalg2.py")
    assert cache.source_key([a]) != key


def test_numba_caches_the_kernels_under_the_key_of_these_sources():
    roots = [REPO / p for p in cache.PACKAGES if (REPO / p).is_dir()]
    path = Path(numba.config.CACHE_DIR)
    assert mpipd.KERNEL_CACHE == path and path.name == cache.source_key(roots)
    from mpipd.kernels.linalg import det3
    assert Path(det3._cache._cache_path).is_relative_to(path)


def test_a_changed_module_gets_a_fresh_cache_and_old_ones_are_pruned(tmp_path):
    """Import a copy of mpipd, change a kernel module, import again: two keyed
    directories; one unused for longer than KEEP_DAYS is removed."""
    src = _tree(tmp_path, "src").parent
    env = dict(os.environ, PYTHONPATH=str(src), MPIPD_KERNEL_CACHE=str(tmp_path / "c"))
    run = [sys.executable, "-c", "import mpipd; print(mpipd.KERNEL_CACHE)"]
    first = Path(subprocess.run(run, env=env, capture_output=True, text=True,
                                check=True, cwd=tmp_path).stdout.strip())
    assert first.parent == tmp_path / "c" and first.is_dir()
    old = time.time() - (cache.KEEP_DAYS + 1) * 86400.0
    os.utime(first, (old, old))
    f = src / "mpipd" / "kernels" / "linalg.py"
    f.write_text(f.read_text() + "\n")
    second = Path(subprocess.run(run, env=env, capture_output=True, text=True,
                                 check=True, cwd=tmp_path).stdout.strip())
    assert second != first and second.is_dir() and not first.exists()


def test_an_editor_lock_file_or_an_unusable_root_does_not_break_the_import(tmp_path):
    """A dangling '.#x.py' (an editor's lock) is no source; a cache root that cannot
    be made (here: below a file) gives a warning, and numba keeps its own cache."""
    src = _tree(tmp_path, "src")
    key = cache.source_key([src])
    (src / "kernels" / ".#nosb.py").symlink_to(tmp_path / "nowhere")
    assert cache.source_key([src]) == key
    (tmp_path / "afile").write_text("")
    env = dict(os.environ, PYTHONPATH=str(src.parent),
               MPIPD_KERNEL_CACHE=str(tmp_path / "afile" / "c"))
    res = subprocess.run([sys.executable, "-W", "always", "-c",
                          "import mpipd, numba; print(mpipd.KERNEL_CACHE, numba.config.CACHE_DIR)"],
                         env=env, capture_output=True, text=True, cwd=tmp_path)
    assert res.returncode == 0, res.stderr
    assert res.stdout.split()[0] == "None" and "no keyed kernel cache" in res.stderr
    assert "afile" not in res.stdout


def test_two_processes_name_their_compiled_functions_apart():
    """numba's symbol ids are random after ``import mpipd``: the first function each of
    two processes compiles gets a different symbol (with counted ids both are ``v1``-like,
    and cached libraries of two processes could bind one body for both: numba #10486)."""
    script = ("import mpipd, numba\n"
              "f = numba.njit(lambda x: x + 1)\n"
              "f(1)\n"
              "print(next(iter(f.overloads.values())).fndesc.mangled_name)\n")
    names = [subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                            check=True).stdout.strip() for _ in range(2)]
    assert names[0] and names[1]
    assert names[0] != names[1]
    assert "$" not in names[0]                          # a mangled symbol, not a Python name
