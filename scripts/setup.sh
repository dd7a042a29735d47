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
#   HEARTBEAT_S=6            seconds between the "still running" lines of a long step
#   SYSTEM_TOOLS=0           leave the system tools alone (.ci/run: the other end's setup,
#                            running beside this one, installs them; apt-get takes one lock)
#   WARM_UP_WORKERS=1        compile the numba kernels in one process, not two (.ci/run: the
#                            other end compiles beside this one; the step "compile" below)
# An existing environment built on another Python version than the one chosen is rebuilt.
#
# Progress: every step prints what it does when it starts and how long it took when it ends
# ("setup: <step> ...", "setup: <step>: done in N s"), and while a step runs a background
# heartbeat prints "setup: <step>: still running, N s" every HEARTBEAT_S seconds, so the script
# is never silent for more than ~HEARTBEAT_S seconds (apt-get, pip and the compile are otherwise
# silent for minutes).  A failing step ends the script with that step's exit code and the line
# "setup: FAILED: <step> (exit N after M s)" (Ctrl-C: "setup: interrupted during <step>", exit
# 130); the heartbeat is stopped on every way out (the EXIT trap: success, a failure under
# `set -e`, Ctrl-C, SIGTERM).
set -euo pipefail
cd "$(dirname "$0")/.."

HEARTBEAT_S=${HEARTBEAT_S:-6}
step_name=""
step_t0=$SECONDS
heartbeat_pid=""

say() { echo "setup: $*" >&2; }

# The background loop of step_begin: a line every HEARTBEAT_S s until it is sent SIGTERM.  Its
# sleep runs in the background and is waited for, so that the TERM trap runs at once (bash
# defers a trap until a foreground child ends) and kills and reaps the sleep too (no orphan left
# holding the terminal or a pipe open, no zombie).
heartbeat() {
  local sleeper=""
  trap '' INT  # Ctrl-C is the script's: its EXIT trap stops this loop with TERM, sleep reaped
  trap '[ -z "$sleeper" ] || { kill "$sleeper" 2>/dev/null; wait "$sleeper" 2>/dev/null; }; exit 0' TERM
  while :; do
    sleep "$HEARTBEAT_S" & sleeper=$!
    wait "$sleeper" || true
    echo "setup: $1: still running, $((SECONDS - $2)) s" >&2
  done
}

stop_heartbeat() {
  if [ -n "$heartbeat_pid" ]; then
    kill "$heartbeat_pid" 2>/dev/null || true
    wait "$heartbeat_pid" 2>/dev/null || true
    heartbeat_pid=""
  fi
}

# step_begin NAME "what it does": the start line ("setup: NAME: what it does ...") and the
# heartbeat ("setup: NAME: still running, N s"); step_end: "setup: NAME: done in N s".
step_begin() {
  stop_heartbeat
  step_name=$1
  step_t0=$SECONDS
  say "$1: $2 ..."
  heartbeat "$step_name" "$step_t0" >/dev/null &
  heartbeat_pid=$!
}

step_end() {
  stop_heartbeat
  say "$step_name: done in $((SECONDS - step_t0)) s"
  step_name=""
}

on_exit() {
  local rc=$?
  trap - EXIT
  trap '' INT TERM  # a second Ctrl-C must not cut the clean-up short (the heartbeat left running)
  stop_heartbeat
  if [ "$rc" = 130 ] || [ "$rc" = 143 ]; then
    say "interrupted${step_name:+ during $step_name} (exit $rc after $SECONDS s in all)"
  elif [ "$rc" != 0 ] && [ -n "$step_name" ]; then
    say "FAILED: $step_name (exit $rc after $((SECONDS - step_t0)) s)"
  fi
  exit "$rc"
}
trap on_exit EXIT
trap 'exit 130' INT
trap 'exit 143' TERM

need=()
command -v dot >/dev/null 2>&1 || need+=(graphviz)
command -v chromium >/dev/null 2>&1 || need+=(chromium)
if [ "${SYSTEM_TOOLS:-1}" = 0 ]; then
  say "system tools: not checked (SYSTEM_TOOLS=0)"
elif [ ${#need[@]} -gt 0 ]; then
  if [ "$(id -u)" = 0 ]; then SUDO=""; elif command -v sudo >/dev/null 2>&1; then SUDO="sudo"; else SUDO="none"; fi
  if [ "$SUDO" = none ]; then
    say "cannot install ${need[*]} (not root, no sudo); the tests that need them will fail"
  else
    step_begin "apt-get update" "the package lists, to install ${need[*]}"
    $SUDO apt-get update -qq >/dev/null
    step_end
    step_begin "apt-get install" "${need[*]}"
    DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${need[@]}" >/dev/null
    step_end
  fi
else
  say "graphviz and chromium are installed"
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

if [ -n "${PYTHON:-}" ]; then
  PY=$PYTHON
else
  step_begin "python" "choosing the newest Python >= 3.10 that has a Drake wheel (asks the package index)"
  PY=$(choose_python)
  step_end
fi
want=$("$PY" -c 'import sys; print("%d.%d" % sys.version_info[:2])')
say "Python $want: $PY"
if [ -x "$VENV/bin/python" ]; then
  have=$("$VENV/bin/python" -c 'import sys; print("%d.%d" % sys.version_info[:2])' 2>/dev/null || echo none)
  if [ "$have" != "$want" ]; then
    say "$VENV has Python $have, rebuilding it with $want"
    rm -rf "$VENV"
  fi
fi
if [ -x "$VENV/bin/python" ]; then
  say "$VENV exists (Python $want): updating it"
else
  step_begin "venv" "creating $VENV"
  "$PY" -m venv "$VENV"
  step_end
fi
step_begin "pip upgrade" "pip itself, in $VENV"
"$VENV/bin/python" -m pip install -q --upgrade pip 2>&1 | quiet_pip
step_end
drake=${DRAKE:-drake}
if [ "${PTINT_EDITABLE:-0}" = 1 ]; then
  step_begin "pip install" "ptint_drake (editable) with $drake, numba and the test, docs and cluster extras"
  "$VENV/bin/python" -m pip install -q -e ".[test,docs,cluster]" "$drake" 2>&1 | quiet_pip
  step_end
else
  step_begin "pip install ptint_drake" "the package, from this tree"
  "$VENV/bin/python" -m pip install -q --force-reinstall --no-deps . 2>&1 | quiet_pip
  step_end
  step_begin "pip install dependencies" "$drake, numba, the test, docs and cluster extras (a first install downloads ~0.5 GB)"
  "$VENV/bin/python" -m pip install -q ".[test,docs,cluster]" "$drake" 2>&1 | quiet_pip
  step_end
fi
# without DRAKE=, bring an existing environment up to the newest Drake its Python admits
if [ -z "${DRAKE:-}" ]; then
  step_begin "pip upgrade drake" "Drake up to the newest release this Python admits"
  "$VENV/bin/python" -m pip install -q --upgrade --upgrade-strategy only-if-needed "drake" 2>&1 | quiet_pip
  step_end
fi
# check the installed package (from outside the source tree) finds its bundled model
venv_abs=$(cd "$VENV" && pwd)
step_begin "check" "the installed package finds its bundled model"
(cd / && "$venv_abs/bin/python" -c "import ptint_drake.robot.rvm1 as r; assert r.model_path().is_file(), r.model_path()")
step_end
# Compile the controller's numba kernels once (into numba's cache), so the first `ptint run`
# does not pay for it; the warm-up prints a line per run it compiles.  Two processes compile
# disjoint kernels side by side (ptint_drake/cli/warm_up.py): a cold cache took 49 s, against 73 s
# in one process, on a 2-core x86_64 machine with nothing else running (2026-12-06, Python 3.13,
# Drake 1.58); on a slower 2-core AMD EPYC machine 97 s against 148 s (2026-12-07).  .ci/run sets
# WARM_UP_WORKERS=1 for its two ends' setups side by side (162 s and 177 s there); a warm cache
# takes a few seconds.
step_begin "compile" "the controller's numba kernels, once (about 1 min when numba's cache is cold, seconds when warm)"
(cd / && "$venv_abs/bin/python" -m ptint_drake.cli.warm_up --workers "${WARM_UP_WORKERS:-2}")
step_end
info=$("$venv_abs/bin/python" -c 'import sys, importlib.metadata as m
print("Python %s, Drake %s" % (sys.version.split()[0], m.version("drake")))')
say "ready in $SECONDS s ($VENV/bin/ptint): $info (from $PY)"
say "next: $VENV/bin/ptint paper   (then open out/paper/index.html in a browser)"
