#!/usr/bin/env bash
# Mutation testing of studio/core with mutmut 3: every small change mutmut makes to a core
# function must turn one of the fast tests ([tool.mutmut] in pyproject.toml: numpy only, no GL
# or Qt) that call that function red. mutmut records which tests call which function and runs
# only those for each mutant.
#
# Usage: bash scripts/mutation.sh [mutant-name-glob ...]
#   JOBS=N   parallel mutants (default: the number of cores)
#   VENV=dir the virtualenv (default .venv, as scripts/test.sh makes it)
# With no argument the whole of studio/core is mutated afresh (about 11 000 mutants; hours on
# two cores). With globs ("studio.core.wrinkles.wdv*") only those mutants are (re)run, reusing mutants/.
# At the end it prints the score per module and overall (killed + timed out over all tested)
# and writes the survivors to mutants/survivors.txt; `$VENV/bin/mutmut show NAME` shows one.
# Run it on a quiet machine: a timed-out mutant counts as killed (mutmut's rule; the timeout
# is fifteen times the tests' own time, so a busy machine rarely fakes one).
set -euo pipefail
cd "$(dirname "$0")/.."
VENV=${VENV:-.venv}
# one thread per mutant: the workers already fill the cores
export OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1 MKL_NUM_THREADS=1
"$VENV/bin/python" -m pip install -q "mutmut>=3.3,<4"
if [ "$#" -eq 0 ]; then
    rm -rf mutants
fi
"$VENV/bin/mutmut" run --max-children "${JOBS:-$(nproc)}" "$@" || true
"$VENV/bin/python" scripts/mutation_report.py
