#!/usr/bin/env bash
# Install Debian's ParaView and a virtual X server for tests/test_paraview.py (`make test`
# runs this; `make demo` does not need it), idempotently: nothing to do once they are
# there.  The packages, without their recommends (docs, a second MPI):
#   paraview          pvbatch and the readers
#   python3-paraview  paraview.simple, which pvbatch needs to run a script; it is only
#                     a Recommends of paraview, so --no-install-recommends alone leaves
#                     a pvbatch that cannot run the test's script
#   xvfb, xauth       Xvfb and xvfb-run: Debian's ParaView renders only through X (it has
#                     no offscreen build; without a display pvbatch aborts with "bad X
#                     server connection"), so a picture made headless needs a virtual
#                     display (the test starts its own Xvfb; scripts/docs_figures.sh
#                     runs pvbatch under xvfb-run, which needs xauth)
set -euo pipefail
APT_PKGS="paraview python3-paraview xvfb xauth"

missing=""
for p in $APT_PKGS; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing="$missing $p"
done
if command -v pvbatch >/dev/null && command -v Xvfb >/dev/null && [ -z "$missing" ]; then
  exit 0
fi
echo "install_paraview: installing Debian packages:$missing (no recommends)"
SUDO=""
[ "$(id -u)" = 0 ] || SUDO="sudo"
$SUDO apt-get update -qq
$SUDO env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends $missing
for c in pvbatch Xvfb xvfb-run; do
  command -v $c >/dev/null || { echo "install_paraview: no $c after installing$missing" >&2; exit 1; }
done
echo "install_paraview: done ($(command -v pvbatch), $(command -v Xvfb))"
