#!/usr/bin/env bash
# Install Debian's LAMMPS, the side-by-side peer of `make bench` (../shared/peers/lammps,
# peri/lps), idempotently: nothing to do once `lmp` is there.  `make bench` runs this;
# without apt-get (or if it fails) the bench runs without its peer and says so.
set -uo pipefail
command -v lmp >/dev/null && exit 0
command -v apt-get >/dev/null || { echo "install_lammps: no lmp and no apt-get: the bench runs without its peer"; exit 0; }
echo "install_lammps: installing Debian's lammps"
SUDO=""
[ "$(id -u)" = 0 ] || SUDO="sudo"
if ! { $SUDO apt-get update -qq && $SUDO env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq lammps; }; then
  echo "install_lammps: apt-get failed: the bench runs without its peer"
  exit 0
fi
echo "install_lammps: done ($(command -v lmp))"
