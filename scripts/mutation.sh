#!/usr/bin/env bash
# Mutation testing of the core formulas with mutmut: every small change mutmut makes to the
# modules named in pyproject.toml ([tool.mutmut] only_mutate) must turn one of their tests red.
# Usage: bash scripts/mutation.sh   (after scripts/test.sh has set up .venv); then
#        .venv/bin/mutmut results   lists the mutants that survived, .venv/bin/mutmut show NAME
# shows one. Run it on a quiet machine: a timed-out mutant counts as killed, and a busy machine
# times out mutants that would have been killed.
set -euo pipefail
cd "$(dirname "$0")/.."
.venv/bin/python -m pip install -q "mutmut>=3.3"
rm -rf mutants
.venv/bin/mutmut run
