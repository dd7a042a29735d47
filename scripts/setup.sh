#!/usr/bin/env bash
# Install everything ptint_drake needs on a fresh Debian machine, idempotently:
#   system tools: graphviz (`ptint diagram`), chromium (the replay browser test)
#   a virtual environment (default .venv) with the package and its test, docs (the Sphinx site:
#   .venv/bin/sphinx-build -W -b html docs docs/_build/html) and cluster (Dask) extras.
#
# Python: the newest Python >= 3.10 found that has a Drake wheel on the package index
# (python3.14 ... python3.10 and python3 on PATH, then ~/.pyenv/versions/*/bin/python), so a
# machine with Python 3.12+ gets the newest Drake and one with only 3.10/3.11 gets Drake 1.51.1
# (the last release with wheels for them).  Variables:
#   PYTHON=/path/to/python   use this interpreter (no search)
#   VENV=dir                 the environment to create or update (default .venv)
#   DRAKE='drake==1.51.1'    a pip requirement for Drake (default: the newest the Python admits)
#   PTINT_EDITABLE=1         install the package in editable mode (for development)
# An existing environment built on another Python version than the one chosen is rebuilt.
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

VENV=${VENV:-.venv}
quiet_pip() { grep -v "^WARNING: Location" || true; }

# "MAJOR.MINOR REALPATH" of a working interpreter >= 3.10 that can make a venv, else nothing.
probe() {
  "$1" -c 'import sys, os, venv, ensurepip
if sys.version_info >= (3, 10): print("%d.%d" % sys.version_info[:2], os.path.realpath(sys.executable))' \
    2>/dev/null || true
}

choose_python() {
  local c found=() line
  for c in python3.14 python3.13 python3.12 python3.11 python3.10 python3 \
           "$HOME"/.pyenv/versions/*/bin/python; do
    command -v "$c" >/dev/null 2>&1 || [ -x "$c" ] || continue
    line=$(probe "$c")
    [ -n "$line" ] && found+=("$line")
  done
  [ ${#found[@]} -gt 0 ] || { echo "setup: no Python >= 3.10 with venv found (set PYTHON=)" >&2; return 1; }
  # newest first, one entry per interpreter; the first one the index has a Drake wheel for wins
  mapfile -t found < <(printf '%s\n' "${found[@]}" | sort -t' ' -k1,1Vr | awk '!seen[$2]++')
  for line in "${found[@]}"; do
    if "${line#* }" -m pip index versions drake >/dev/null 2>&1; then
      echo "${line#* }"; return 0
    fi
  done
  echo "setup: could not ask the package index about Drake; using the newest Python" >&2
  echo "${found[0]#* }"
}

PY=${PYTHON:-$(choose_python)}
want=$("$PY" -c 'import sys; print("%d.%d" % sys.version_info[:2])')
if [ -x "$VENV/bin/python" ]; then
  have=$("$VENV/bin/python" -c 'import sys; print("%d.%d" % sys.version_info[:2])' 2>/dev/null || echo none)
  if [ "$have" != "$want" ]; then
    echo "setup: $VENV has Python $have, rebuilding it with $want" >&2
    rm -rf "$VENV"
  fi
fi
[ -x "$VENV/bin/python" ] || "$PY" -m venv "$VENV"
"$VENV/bin/python" -m pip install -q --upgrade pip 2>&1 | quiet_pip
drake=${DRAKE:-drake}
if [ "${PTINT_EDITABLE:-0}" = 1 ]; then
  "$VENV/bin/python" -m pip install -q -e ".[test,docs,cluster]" "$drake" 2>&1 | quiet_pip
else
  "$VENV/bin/python" -m pip install -q --force-reinstall --no-deps . 2>&1 | quiet_pip
  "$VENV/bin/python" -m pip install -q ".[test,docs,cluster]" "$drake" 2>&1 | quiet_pip
fi
# without DRAKE=, bring an existing environment up to the newest Drake its Python admits
[ -n "${DRAKE:-}" ] || "$VENV/bin/python" -m pip install -q --upgrade --upgrade-strategy only-if-needed \
  "drake" 2>&1 | quiet_pip
# check the installed package (from outside the source tree) finds its bundled model
venv_abs=$(cd "$VENV" && pwd)
(cd / && "$venv_abs/bin/python" -c "import ptint_drake.rvm1 as r; assert r.model_path().is_file(), r.model_path()")
# compile the controller's numba kernels once (into numba's cache), so the first `ptint run`
# does not pay for it (about 30-70 s of CPU on a cold cache; a few seconds when already warm)
(cd / && "$venv_abs/bin/python" -m ptint_drake.warm_up)
info=$("$venv_abs/bin/python" -c 'import sys, importlib.metadata as m
print("Python %s, Drake %s" % (sys.version.split()[0], m.version("drake")))')
echo "setup: ready ($VENV/bin/ptint): $info (from $PY)" >&2
