#!/usr/bin/env bash
# Install Debian's ParaView for tests/test_paraview.py (`make test` runs this; `make demo`
# does not need it), idempotently: nothing to do once pvbatch and ParaView's Python
# modules are there.  Both packages, without their recommends (docs, a second MPI):
#   paraview          pvbatch and the readers
#   python3-paraview  paraview.simple, which pvbatch needs to run a script; it is only
#                     a Recommends of paraview, so --no-install-recommends alone leaves
#                     a pvbatch that cannot run the test's script
set -euo pipefail
APT_PKGS="paraview python3-paraview"

missing=""
for p in $APT_PKGS; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing="$missing $p"
done
if command -v pvbatch >/dev/null && [ -z "$missing" ]; then
  exit 0
fi
echo "install_paraview: installing Debian packages:$missing (no recommends)"
SUDO=""
[ "$(id -u)" = 0 ] || SUDO="sudo"
$SUDO apt-get update -qq
$SUDO env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends $missing
command -v pvbatch >/dev/null || { echo "install_paraview: no pvbatch after installing paraview" >&2; exit 1; }
echo "install_paraview: done ($(command -v pvbatch))"
