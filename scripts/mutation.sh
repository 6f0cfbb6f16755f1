#!/usr/bin/env bash
# Mutation testing of studio/core with mutmut 3: every small change mutmut makes to a core
# function must turn one of the fast tests (marked `core`: numpy only, in-process) that call
# that function red. mutmut records which tests call which function and runs only those for
# each mutant; its results stay in mutants/ and a later run re-tests only the functions whose
# code changed since (the cache). Each run also saves the results to BASELINE (committed, a
# hundred kilobytes): a run that finds no mutants/ (a fresh clone, another machine) starts from
# those, so a measurement that takes longer than one sitting carries on where it stopped.
#
# Usage: bash scripts/mutation.sh [--fresh | --recheck | --formulas | MODULE.py ... ]
#   no argument   the whole of studio/core (about 28 500 mutants: a first run takes several
#                 hours on two cores, a later one re-tests only what changed)
#   --fresh       the whole of studio/core, the cache and the saved results dropped first
#   --recheck     only the mutants not caught last time (survived, or no test called them):
#                 the run to make after writing tests that should kill them
#   --formulas    the modules holding the techniques' formulas and the shaders' numpy
#                 references (FORMULAS below)
#   MODULE.py ... those files only (paths like studio/core/wrinkles/wdv.py)
#   --check MUTANT TEST...   run the given tests against one mutant (killed: they fail), e.g.
#                 --check studio.core.wrinkles.wdv.x_visibility__mutmut_3 tests/test_wdv_slots.py
#   JOBS=N   parallel mutants (default: the number of cores)
#   VENV=dir the virtualenv (default .venv, as scripts/test.sh makes it)
#   MUTANT_TEST_SECONDS=S  a mutant gets the tests that call it quickest first, up to S seconds
#            of their measured time (default 2; tests/conftest.py): a mutant only slower tests
#            would catch counts as surviving, so the score is never flattered
# At the end it prints the score per module and overall (killed + timed out over all tested)
# and lists the survivors, each with its changed line, in docs/mutation-survivors.txt (committed);
# `$VENV/bin/mutmut show NAME` shows one whole.
# Run it on a quiet machine: a timed-out mutant counts as killed (mutmut's rule; the timeout
# is fifteen times the tests' own time, so a busy machine rarely fakes one). The property-based
# fuzz tests run 25 examples per mutant (WRINKLE_FUZZ_EXAMPLES) instead of the suite's 250.
set -euo pipefail
cd "$(dirname "$0")/.."
VENV=$(cd "${VENV:-.venv}" && pwd)
BASELINE=tests/mutation-baseline.json.gz
FORMULAS="studio/core/animation/poses.py studio/core/animation/timeline.py
  studio/core/animation/pose_names.py studio/core/mesh/picking.py studio/core/mesh/uv_tiles.py
  studio/core/files/png_unfilter.py studio/core/wrinkles/wdv.py
  studio/core/wrinkles/mask_sparse.py studio/core/wrinkles/influence.py
  studio/core/wrinkles/response.py studio/core/wrinkles/strain.py
  studio/core/wrinkles/normalmap.py"
JOBS=${JOBS:-$(nproc)}  # before OMP_NUM_THREADS is set: GNU nproc obeys it
# one thread per mutant: the workers already fill the cores
export OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1 MKL_NUM_THREADS=1
export WRINKLE_FUZZ_EXAMPLES=${WRINKLE_FUZZ_EXAMPLES:-25}
"$VENV/bin/python" -m pip install -q "mutmut>=3.8,<4"

if [ "${1:-}" = "--check" ]; then
    [ "$#" -ge 3 ] || { echo "usage: mutation.sh --check MUTANT TEST..." >&2; exit 2; }
    mutant=$2; shift 2
    [ -d mutants/tests ] || { echo "no mutants/ yet: run mutation.sh first" >&2; exit 2; }
    for test in "$@"; do cp "${test%%::*}" "mutants/${test%%::*}"; done
    if (cd mutants && MUTANT_UNDER_TEST=$mutant "$VENV/bin/python" -m pytest -p no:xvfb \
            -p no:cacheprovider -q -x "$@"); then
        echo "$mutant survives these tests"; exit 1
    fi
    echo "$mutant is killed"; exit 0
fi

names=()
if [ "${1:-}" = "--fresh" ]; then
    rm -rf mutants
elif [ -f "$BASELINE" ] && ! compgen -G "mutants/studio/core/*/*.meta" >/dev/null; then
    "$VENV/bin/python" scripts/mutation_report.py --restore "$BASELINE"
fi
case "${1:-}" in
    --fresh) ;;
    --recheck)
        mapfile -t names < <("$VENV/bin/python" scripts/mutation_report.py --not-caught)
        [ "${#names[@]}" -gt 0 ] || { echo "nothing left to recheck"; exit 0; } ;;
    --formulas) for f in $FORMULAS; do names+=("$(echo "${f%.py}" | tr / .).*"); done ;;
    "") ;;
    *) for f in "$@"; do names+=("$(echo "${f%.py}" | tr / .).*"); done ;;
esac
"$VENV/bin/mutmut" run --max-children "$JOBS" "${names[@]}" || true
"$VENV/bin/python" scripts/mutation_report.py --save "$BASELINE"
"$VENV/bin/python" scripts/mutation_report.py
