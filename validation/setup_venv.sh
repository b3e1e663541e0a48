#!/usr/bin/env bash
# Create (or reuse) validation/.venv with the pinned requirements.
#
#   validation/setup_venv.sh            # idempotent; PYTHON=python3.11 to pick the interpreter
#
# The venv is reused as long as the stamp file (.venv/.requirements.sha256) holds the hash of
# requirements.txt and of the interpreter version; otherwise the pins are (re)installed.
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
venv="$here/.venv"
req="$here/requirements.txt"
stamp="$venv/.requirements.sha256"
PY="${PYTHON:-python3}"

die() { echo "setup_venv.sh: $*" >&2; exit 1; }

command -v "$PY" >/dev/null 2>&1 || die "'$PY' not found; install Python >= 3.11 or set PYTHON=/path/to/python3"
"$PY" -c 'import sys; sys.exit(0 if sys.version_info >= (3, 11) else 1)' \
  || die "$("$PY" -V 2>&1) is too old: scipy 1.17.1 / numpy 2.4.6 need Python >= 3.11 (set PYTHON=...)"

# Hash of the requirements and of the interpreter version (a new Python needs new wheels).
hash="$("$PY" - "$req" <<'PYEOF'
import hashlib, sys
h = hashlib.sha256(open(sys.argv[1], "rb").read())
h.update(sys.version.encode())
print(h.hexdigest())
PYEOF
)"

if [ -x "$venv/bin/python" ] && "$venv/bin/python" -c 'pass' 2>/dev/null \
   && [ -f "$stamp" ] && [ "$(cat "$stamp")" = "$hash" ]; then
  echo "validation/.venv is up to date ($(cat "$req" | grep -c '==') pins)"
  exit 0
fi

if [ ! -x "$venv/bin/python" ] || ! "$venv/bin/python" -c 'pass' 2>/dev/null; then
  if ! "$PY" -c 'import ensurepip, venv' 2>/dev/null; then
    die "the 'venv'/'ensurepip' modules are missing from $("$PY" -V 2>&1).
  Debian/Ubuntu: sudo apt-get install python3-venv   (or python3.11-venv for that exact version)
  Fedora/RHEL:   sudo dnf install python3           (venv is included)
  pyenv/conda pythons include it; alternatively: $PY -m venv --without-pip $venv && curl -sS https://bootstrap.pypa.io/get-pip.py | $venv/bin/python"
  fi
  rm -rf "$venv"
  if ! "$PY" -m venv "$venv"; then
    rm -rf "$venv"
    die "'$PY -m venv' failed (on Debian/Ubuntu: sudo apt-get install python3-venv)"
  fi
fi

rm -f "$stamp"
"$venv/bin/python" -m pip install --disable-pip-version-check -r "$req"
"$venv/bin/python" -c 'import numpy, scipy, matplotlib, pytest, fmpy, libcosimpy, dask, distributed' \
  || die "packages installed but do not import"
echo "$hash" > "$stamp"
echo "validation/.venv ready: $("$venv/bin/python" -V)"
