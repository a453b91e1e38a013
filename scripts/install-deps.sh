#!/usr/bin/env bash
# Installs what a fresh Debian machine with only Rust lacks: the HDF5 library the solvers write
# with, the font/plot libraries of `fsi plot`, and the Python readers the output tests use.
# Idempotent: does nothing when everything is present.
set -euo pipefail

apt_packages=(libhdf5-dev pkg-config libfontconfig1-dev libfreetype-dev fonts-dejavu-core)
missing=()
for p in "${apt_packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "install-deps: installing ${missing[*]}"
  sudo_cmd=""
  [ "$(id -u)" -ne 0 ] && sudo_cmd="sudo"
  $sudo_cmd apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo_cmd apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

# Real readers for the output tests (meshio + h5py read our XDMF/HDF5).
if command -v python3 >/dev/null; then
  if ! python3 -c "import meshio, h5py, numpy" 2>/dev/null; then
    echo "install-deps: installing meshio, h5py, numpy from PyPI"
    python3 -m pip install -q --disable-pip-version-check meshio h5py numpy \
      || python3 -m pip install -q --disable-pip-version-check --break-system-packages meshio h5py numpy
  fi
fi

# The Python structure solver's venv (coupler-scripts/python: iceoryx2 0.10.0, numpy).
if command -v python3 >/dev/null; then
  bash "$(dirname "${BASH_SOURCE[0]}")/../coupler-scripts/python/install.sh"
fi
