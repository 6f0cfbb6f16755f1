#!/usr/bin/env bash
# Installs Wrinkle Studio and opens it on the bundled sample face. On a machine without a screen it
# runs the window on a virtual display, saves a screenshot and says where it wrote it.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
if [ -n "${DISPLAY:-}${WAYLAND_DISPLAY:-}" ]; then
  exec .venv/bin/wrinkle-studio "$@"
fi
echo "no screen here: running the studio on a virtual display and saving a screenshot"
exec xvfb-run -a -s "-screen 0 1600x1000x24" .venv/bin/wrinkle-studio --screenshot studio-screenshot.png "$@"
