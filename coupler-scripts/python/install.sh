#!/usr/bin/env bash
# Installs the Python structure solver's packages (iceoryx2 0.10.0, numpy) into the project-local
# venv .venv-python-peer/ at the repository root; nothing system-wide. Idempotent: does nothing
# when the venv already has them.
set -euo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
venv="$root/.venv-python-peer"
py="$venv/bin/python"

if [ -x "$py" ] && "$py" -c 'import numpy, iceoryx2, importlib.metadata as m; assert m.version("iceoryx2") == "0.10.0"' 2>/dev/null; then
  exit 0
fi
command -v python3 >/dev/null || { echo "install.sh: python3 (>= 3.11) is needed" >&2; exit 1; }
python3 -c 'import sys; sys.exit(sys.version_info < (3, 11))' \
  || { echo "install.sh: python3 >= 3.11 is needed (tomllib)" >&2; exit 1; }
site="$venv/site"
if [ -d "$site" ] && PYTHONPATH="$site" python3 -c 'import numpy, iceoryx2, importlib.metadata as m; assert m.version("iceoryx2") == "0.10.0"' 2>/dev/null; then
  exit 0
fi
if [ ! -x "$py" ]; then
  echo "install.sh: creating $venv"
  if ! python3 -m venv "$venv" 2>/dev/null; then
    # No venv module (Debian without python3-venv): the packages go into $venv/site instead,
    # which the `spring-mass` wrapper puts on PYTHONPATH of the system python3.
    rm -rf "$venv"
    echo "install.sh: python3 -m venv is unavailable; installing into $site"
    python3 -m pip install -q --disable-pip-version-check --target "$site" "iceoryx2==0.10.0" numpy
    exit 0
  fi
fi
echo "install.sh: installing iceoryx2==0.10.0 and numpy into $venv"
"$py" -m pip install -q --disable-pip-version-check "iceoryx2==0.10.0" numpy
