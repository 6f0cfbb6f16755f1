#!/usr/bin/env bash
# Installs Wrinkle Studio into .venv on a fresh Debian 12 / Python 3.11 machine: the Debian
# packages for OpenGL (Mesa EGL), Xvfb and Qt's xcb platform, then the Python packages.
# Usage: bash scripts/setup.sh [pip extras, e.g. test]
set -euo pipefail
cd "$(dirname "$0")/.."
packages=$(cat resources/debian-packages.txt)
missing=$(dpkg-query -W -f='${Status} ${Package}\n' $packages 2>/dev/null \
          | grep -v '^install ok installed' | awk '{print $NF}' || true)
missing="$missing $(for p in $packages; do dpkg-query -W "$p" >/dev/null 2>&1 || echo "$p"; done)"
python3 -m venv --help >/dev/null 2>&1 || missing="$missing python3-venv"
if [ -n "${missing// /}" ] && command -v apt-get >/dev/null; then
  sudo=""; [ "$(id -u)" = 0 ] || sudo="sudo"
  echo "installing Debian packages:$missing"
  $sudo env DEBIAN_FRONTEND=noninteractive apt-get update -qq
  $sudo env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends \
    $missing >/dev/null
fi
[ -x .venv/bin/python ] || python3 -m venv .venv
.venv/bin/python -m pip install -q --upgrade pip >/dev/null
extras=${1:-}
.venv/bin/python -m pip install -q -e ".${extras:+[$extras]}"
