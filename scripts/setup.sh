#!/usr/bin/env bash
# Installs Wrinkle Studio into .venv on a fresh Debian 12 / Python 3.11 machine: the Debian
# packages for OpenGL (Mesa EGL), Xvfb, Qt's xcb platform and Node.js, then the Python packages
# (and, with the test extra, the Khronos glTF validator from npm).
# Usage: bash scripts/setup.sh [pip extras, e.g. test]
set -euo pipefail
cd "$(dirname "$0")/.."
packages=$(cat resources/debian-packages.txt)
# Node may already be there from elsewhere (NodeSource ships npm inside its nodejs, and Debian's
# npm then conflicts with it): ask Debian for nodejs and npm only when they are missing
if command -v node >/dev/null && command -v npm >/dev/null; then
  packages=$(printf '%s\n' $packages | grep -vx -e nodejs -e npm)
fi
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
# The tests run the Khronos glTF validator over every export (tests/test_gltf_validator.py) and
# play the exports' wrinkles.js on three.js (tests/test_three_wrinkles.py): their npm packages,
# pinned, into .node/ (git-ignored), read by scripts/validate_gltf.js and the three.js tests.
if [[ ",$extras," == *",test,"* ]]; then
  npm install --silent --no-audit --no-fund --prefix .node gltf-validator@2.0.0-dev.3.10 \
    three@0.160.1 >/dev/null
fi
