#!/usr/bin/env bash
# Set up everything mpipd needs on a Debian machine, idempotently:
#   1. Debian packages: Open MPI and the MPI build of HDF5 (apt, needs root or sudo)
#   2. a virtualenv at .venv with numpy, scipy, numba, pytest
#   3. mpi4py built against the system Open MPI, h5py built against parallel HDF5
#   4. mpipd itself, editable, and the pinned tools of its documentation site
#      (pyproject.toml's `docs` extra: mkdocs-material, mkdocstrings; `make docs`)
# Fails loudly if h5py lacks MPI support.
set -euo pipefail
cd "$(dirname "$0")/.."
VENV=${VENV:-.venv}
APT_PKGS="openmpi-bin libopenmpi-dev libhdf5-openmpi-dev pkg-config"

missing=""
for p in $APT_PKGS; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing="$missing $p"
done
if [ -n "$missing" ]; then
  echo "bootstrap: installing Debian packages:$missing"
  SUDO=""
  [ "$(id -u)" = 0 ] || SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq $missing
fi

if [ ! -x "$VENV/bin/python" ]; then
  echo "bootstrap: creating $VENV"
  python3 -m venv "$VENV"
fi
PY="$VENV/bin/python"
"$PY" -m pip install -q --upgrade pip "setuptools>=70" wheel
"$PY" -m pip install -q numpy scipy numba pytest matplotlib "cython>=3" pkgconfig "ruff==0.17.6"

# mpi4py and h5py from source against the system MPI / parallel HDF5.
if ! "$PY" -c "import mpi4py" 2>/dev/null; then
  echo "bootstrap: building mpi4py against $(command -v mpicc)"
  MPICC=mpicc "$PY" -m pip install -q --no-binary=mpi4py mpi4py
fi
if ! "$PY" -c "import h5py, sys; sys.exit(0 if h5py.get_config().mpi else 1)" 2>/dev/null; then
  echo "bootstrap: building h5py against parallel HDF5 (2-3 minutes the first time)"
  "$PY" -m pip uninstall -q -y h5py 2>/dev/null || true
  HDF5_MPI=ON CC=mpicc HDF5_PKGCONFIG_NAME=hdf5-openmpi \
    "$PY" -m pip install -q --no-binary=h5py --no-build-isolation h5py
fi
"$PY" -c "import h5py, sys; ok = h5py.get_config().mpi; print('bootstrap: h5py', h5py.__version__, 'mpi =', ok); sys.exit(0 if ok else 1)" \
  || { echo "bootstrap: h5py was built WITHOUT MPI support; parallel output cannot work" >&2; exit 1; }

"$PY" -m pip install -q --no-deps --no-build-isolation -e .
# the docs extra's pins, read from pyproject.toml (not `pip install -e .[docs]`, which
# would also resolve h5py and mpi4py again, from wheels without MPI)
"$PY" - <<'PYEOF' > "$VENV/.docs-requirements.txt"
import tomllib
print("\n".join(tomllib.load(open("pyproject.toml", "rb"))["project"]["optional-dependencies"]["docs"]))
PYEOF
"$PY" -m pip install -q -r "$VENV/.docs-requirements.txt"
echo "bootstrap: done"
