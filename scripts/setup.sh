#!/usr/bin/env bash
# Install everything ptint_drake needs on a fresh Debian machine, idempotently:
#   system tools: graphviz (`ptint diagram`), chromium (the replay browser test)
#   a virtual environment .venv with the package and its test and cluster (Dask) extras.
# PTINT_EDITABLE=1 installs the package in editable mode (for development).
set -euo pipefail
cd "$(dirname "$0")/.."

need=()
command -v dot >/dev/null 2>&1 || need+=(graphviz)
command -v chromium >/dev/null 2>&1 || need+=(chromium)
if [ ${#need[@]} -gt 0 ]; then
  if [ "$(id -u)" = 0 ]; then SUDO=""; elif command -v sudo >/dev/null 2>&1; then SUDO="sudo"; else SUDO="none"; fi
  if [ "$SUDO" = none ]; then
    echo "setup: cannot install ${need[*]} (not root, no sudo); the tests that need them will fail" >&2
  else
    echo "setup: apt-get install ${need[*]}" >&2
    $SUDO apt-get update -qq >/dev/null
    DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${need[@]}" >/dev/null
  fi
fi

PY=${PYTHON:-python3}
[ -x .venv/bin/python ] || "$PY" -m venv .venv
.venv/bin/python -m pip install -q --upgrade pip 2>&1 | grep -v "^WARNING: Location" || true
if [ "${PTINT_EDITABLE:-0}" = 1 ]; then
  .venv/bin/python -m pip install -q -e ".[test,cluster]" 2>&1 | grep -v "^WARNING: Location" || true
else
  .venv/bin/python -m pip install -q --force-reinstall --no-deps . 2>&1 | grep -v "^WARNING: Location" || true
  .venv/bin/python -m pip install -q ".[test,cluster]" 2>&1 | grep -v "^WARNING: Location" || true
fi
# check the installed package (from outside the source tree) finds its bundled model
(cd / && "$OLDPWD/.venv/bin/python" -c "import ptint_drake.rvm1 as r; assert r.model_path().is_file(), r.model_path()")
echo "setup: ready (.venv/bin/ptint)" >&2
