#!/usr/bin/env bash
# Prepare this machine for earl: system packages when missing, a virtual environment, the Python packages.
# Idempotent and quick when everything is already there. Used by `make demo` and `make test`.
set -euo pipefail

VENV="${VENV:-.venv}"
PYTHON="${PYTHON:-python3}"

apt_install() {
    # System packages come from Debian's archive; only root (or sudo) can install them.
    local sudo=""
    if [ "$(id -u)" -ne 0 ]; then
        if command -v sudo >/dev/null 2>&1; then sudo="sudo"; else
            echo "setup: please install these packages first: $*" >&2; exit 1
        fi
    fi
    echo "setup: installing system packages: $*"
    $sudo apt-get update -qq
    DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq "$@" >/dev/null
}

if ! command -v "$PYTHON" >/dev/null 2>&1; then
    apt_install python3 python3-venv
fi
if ! "$PYTHON" -c 'import sys; sys.exit(0 if sys.version_info >= (3, 11) else 1)'; then
    echo "setup: earl needs Python 3.11 or newer; $("$PYTHON" --version) found" >&2
    exit 1
fi
if ! "$PYTHON" -c 'import venv, ensurepip' >/dev/null 2>&1; then
    apt_install python3-venv
fi
# Graphviz's `dot` draws the diagrams of `earl diagram` and `earl doc`.
command -v dot >/dev/null 2>&1 || apt_install graphviz
# MuJoCo renders the pick-and-place pictures offscreen through EGL (docs/simulation.md).
ldconfig -p 2>/dev/null | grep -q 'libEGL.so.1 ' || apt_install libegl1 libgl1
# Headless Chromium opens the generated document in the tests (driven by Playwright, which may not download
# a browser of its own here).
command -v chromium >/dev/null 2>&1 || apt_install chromium

stamp="$VENV/.earl-installed"
if [ ! -f "$stamp" ] || [ pyproject.toml -nt "$stamp" ]; then
    echo "setup: creating $VENV and installing earl with its development tools"
    "$PYTHON" -m venv "$VENV"
    "$VENV/bin/python" -m pip install --quiet --upgrade pip
    "$VENV/bin/python" -m pip install --quiet -e ".[dev]"
    touch "$stamp"
fi
# Byte-compile earl and the examples, as pip does for a regular install (an editable one does not):
# Python then starts from the cached bytecode even where PYTHONDONTWRITEBYTECODE is set, which saves
# compiling ~100 modules (an eighth of a second) at every `earl` command. Stale files are recompiled.
"$VENV/bin/python" -m compileall -q -j 0 src examples >/dev/null
