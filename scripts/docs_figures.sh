#!/usr/bin/env bash
# A damage picture of a run with ParaView, headless: pvbatch runs scripts/paraview_figure.py
# on a virtual X display.  `make docs-figures` makes the tutorial's picture with it:
#   bash scripts/docs_figures.sh runs/docs_figures docs/img/paraview_damage.png
# and any run works the same way, with paraview_figure.py's options after the two paths:
#   bash scripts/docs_figures.sh runs/demo runs/demo/damage_t.png --threshold 0.5 --frame 6
# RUN is a run folder, its run.h5 or its run.xdmf.  Debian's ParaView renders only through
# X, so the script starts an Xvfb of its own (-displayfd: the server picks a free display
# and says when it is ready; stopped at exit); scripts/install_paraview.sh installs
# ParaView and xvfb if they are missing.  pvbatch gets a clean environment: it embeds the
# system Python (the venv's PYTHONPATH would shadow its numpy) and starts as an MPI
# singleton (no launcher variables of an outer mpirun).
set -euo pipefail
cd "$(dirname "$0")/.."
[ $# -ge 2 ] || { echo "usage: bash scripts/docs_figures.sh RUN OUT.png [paraview_figure.py options]" >&2; exit 2; }
run=$1
png=$2
shift 2
{ command -v pvbatch && command -v Xvfb; } >/dev/null || bash scripts/install_paraview.sh
home=$(mktemp -d)
xvfb=""
trap '[ -n "$xvfb" ] && { kill "$xvfb" 2>/dev/null; wait "$xvfb" 2>/dev/null; }; rm -rf "$home"' EXIT
Xvfb -displayfd 3 -nolisten tcp -screen 0 1280x1024x24 3>"$home/display" 2>"$home/xvfb.log" &
xvfb=$!
for _ in $(seq 600); do
  [ -s "$home/display" ] && break
  kill -0 "$xvfb" 2>/dev/null || { echo "docs_figures: Xvfb did not start:" >&2; cat "$home/xvfb.log" >&2; exit 1; }
  sleep 0.1
done
[ -s "$home/display" ] || { echo "docs_figures: Xvfb gave no display in 60 s" >&2; exit 1; }
mkdir -p "$(dirname "$png")"
env -i PATH=/usr/local/bin:/usr/bin:/bin HOME="$home" LANG=C.UTF-8 DISPLAY=":$(cat "$home/display")" \
    OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 \
    pvbatch scripts/paraview_figure.py "$(realpath "$run")" --out "$(realpath -m "$png")" "$@"
