#!/usr/bin/env bash
# Mutation testing of studio/core with mutmut 3: every small change mutmut makes to a core
# function must turn one of the fast tests ([tool.mutmut] in pyproject.toml: numpy only, no GL
# or Qt) that call that function red. mutmut records which tests call which function and runs
# only those for each mutant.
#
# Usage: bash scripts/mutation.sh [MODULE.py ...]
#   no argument   the whole of studio/core (about 26 500 mutants: hours on two cores)
#   --formulas    the modules holding the techniques' formulas and the shaders' numpy
#                 references (FORMULAS below: about 2 800 mutants, 15-25 minutes on two cores)
#   MODULE.py ... those files only (paths like studio/core/wrinkles/wdv.py)
#   JOBS=N   parallel mutants (default: the number of cores)
#   VENV=dir the virtualenv (default .venv, as scripts/test.sh makes it)
# A subset runs in a copy of the working tree whose pyproject names just those files (mutmut 3
# takes the files to mutate from pyproject only); its mutants/ folder is copied back here.
# At the end it prints the score per module and overall (killed + timed out over all tested)
# and writes the survivors to mutants/survivors.txt; `$VENV/bin/mutmut show NAME` (run inside
# the folder that holds mutants/) shows one.
# Run it on a quiet machine: a timed-out mutant counts as killed (mutmut's rule; the timeout
# is fifteen times the tests' own time, so a busy machine rarely fakes one).
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$PWD
VENV=$(cd "${VENV:-.venv}" && pwd)
FORMULAS="studio/core/animation/poses.py studio/core/animation/timeline.py
  studio/core/animation/pose_names.py studio/core/mesh/picking.py studio/core/mesh/uv_tiles.py
  studio/core/files/png_unfilter.py studio/core/wrinkles/wdv.py
  studio/core/wrinkles/mask_sparse.py studio/core/wrinkles/influence.py
  studio/core/wrinkles/response.py studio/core/wrinkles/strain.py
  studio/core/wrinkles/normalmap.py"
# one thread per mutant: the workers already fill the cores
export OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1 MKL_NUM_THREADS=1
"$VENV/bin/python" -m pip install -q "mutmut>=3.3,<4"
files=""
if [ "${1:-}" = "--formulas" ]; then files=$FORMULAS; elif [ "$#" -gt 0 ]; then files="$*"; fi
rm -rf mutants
if [ -z "$files" ]; then
    "$VENV/bin/mutmut" run --max-children "${JOBS:-$(nproc)}" || true
else
    work=$(mktemp -d)
    trap 'rm -rf "$work"' EXIT
    tar --exclude=./.venv --exclude=./mutants --exclude=./.node --exclude=./.git -cf - . \
        | tar -xf - -C "$work"
    "$VENV/bin/python" - "$work/pyproject.toml" $files <<'PY'
import re, sys
from pathlib import Path
path, files = Path(sys.argv[1]), sys.argv[2:]
text, count = re.subn(r"(?m)^only_mutate = .*$",
                      "only_mutate = [" + ", ".join(f'"{f}"' for f in files) + "]",
                      path.read_text())
assert count == 1, "pyproject.toml has no one-line only_mutate"
path.write_text(text)
PY
    (cd "$work" && "$VENV/bin/mutmut" run --max-children "${JOBS:-$(nproc)}") || true
    cp -r "$work/mutants" "$ROOT/mutants"
fi
"$VENV/bin/python" scripts/mutation_report.py
