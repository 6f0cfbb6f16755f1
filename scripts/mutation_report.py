"""Summarise a mutmut run: the score per core module and overall, the survivors listed.

Reads mutants/**/*.meta (mutmut 3's per-file results) and names each exit code as mutmut does
(``mutmut.stats.status_by_exit_code``), so the figure does not depend on mutmut's terminal output.
The score is mutmut's own: (killed + timeout) / (all mutants but the skipped ones); a mutant
that crashed the interpreter ("segfault") or is "suspicious" counts as not caught.
"""

from __future__ import annotations

import json
import sys
from collections import Counter
from pathlib import Path

from mutmut.stats import status_by_exit_code

NOT_CAUGHT = ("survived", "no tests")


def main() -> None:
    """Print the table and write mutants/survivors.txt; with ``--not-caught``, print only the
    names of the mutants not caught (for ``mutation.sh --recheck``)."""
    rows: dict[str, Counter] = {}
    survivors: list[str] = []
    core = Path("mutants/studio/core")
    for meta in sorted(core.rglob("*.py.meta")):
        data = json.loads(meta.read_text())
        counts: Counter = Counter()
        for name, code in data.get("exit_code_by_key", {}).items():
            verdict = status_by_exit_code[code]
            counts[verdict] += 1
            if verdict in NOT_CAUGHT:
                survivors.append(f"{verdict:9} {name}")
        rows[str(meta.relative_to(core)).removesuffix(".py.meta")] = counts
    if "--not-caught" in sys.argv[1:]:
        print("\n".join(line.split()[-1] for line in survivors))
        return
    total: Counter = Counter()
    print(f"{'module':24} {'mutants':>7} {'killed':>7} {'timeout':>7} {'survived':>8} "
          f"{'no tests':>8} {'other':>6} {'score':>6}")
    for module, c in rows.items():
        total.update(c)
        print(line(module, c))
    print(line("studio/core", total))
    Path("mutants/survivors.txt").write_text("\n".join(survivors) + "\n")
    print(f"{len(survivors)} survivors listed in mutants/survivors.txt")


def line(name: str, c: Counter) -> str:
    """A table row; the score is (killed + timeout) / (mutants run, skipped ones excluded)."""
    run = sum(c.values()) - c["skipped"]
    caught = c["killed"] + c["timeout"]
    other = run - caught - c["survived"] - c["no tests"]
    score = f"{100 * caught / run:5.1f}%" if run else "   -  "
    return (f"{name:24} {sum(c.values()):7} {c['killed']:7} {c['timeout']:7} {c['survived']:8} "
            f"{c['no tests']:8} {other:6} {score}")


if __name__ == "__main__":
    main()
