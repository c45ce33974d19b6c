#!/usr/bin/env bash
# The tutorial's ParaView picture: pvbatch renders RUN.xdmf into PNG (make docs-figures).
#   bash scripts/docs_figures.sh RUN/run.xdmf docs/img/paraview_damage.png
# pvbatch (Debian's paraview, scripts/install_paraview.sh) renders through X, so it runs
# under xvfb-run; Debian's xvfb is installed with apt if it is missing.  pvbatch gets a
# clean environment: it embeds the system Python (the venv's PYTHONPATH would shadow its
# numpy) and starts as an MPI singleton (no launcher variables of an outer mpirun).
set -euo pipefail
cd "$(dirname "$0")/.."
xdmf=$1
png=$2
command -v pvbatch >/dev/null || bash scripts/install_paraview.sh
if ! command -v xvfb-run >/dev/null; then
  echo "docs_figures: installing Debian packages: xvfb xauth (no recommends)"
  SUDO=""
  [ "$(id -u)" = 0 ] || SUDO="sudo"
  $SUDO apt-get update -qq
  $SUDO env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends xvfb xauth
fi
home=$(mktemp -d)
trap 'rm -rf "$home"' EXIT
mkdir -p "$(dirname "$png")"
env -i PATH=/usr/local/bin:/usr/bin:/bin HOME="$home" LANG=C.UTF-8 \
    OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 \
    xvfb-run -a -s "-screen 0 1280x1024x24" \
    pvbatch scripts/paraview_figure.py "$(realpath "$xdmf")" "$(realpath -m "$png")"
