#!/usr/bin/env bash
# Installs everything (Debian packages included) and runs the checks: ruff, the import-linter
# contracts (layers, no cycles; pyproject.toml), then the tests.
# Renderer tests use a standalone EGL context; GUI tests run under Xvfb (pytest-xvfb).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh test
.venv/bin/ruff check studio tests
.venv/bin/lint-imports
.venv/bin/python -m pytest -q "$@"
