"""Summarise a mutmut run: the score per core module and overall, the survivors listed.

Reads mutants/**/*.meta (mutmut 3's per-file results) and names each exit code as mutmut does
(``mutmut.stats.status_by_exit_code``), so the figure does not depend on mutmut's terminal output.
The score is mutmut's own: (killed + timeout) / (mutants tested, skipped ones excluded); a
mutant that crashed the interpreter ("segfault") or is "suspicious" counts as not caught, one
not run yet ("not checked") is counted apart and left out of the score.

``--save FILE`` writes the results (each function's hash and each mutant's exit code) to a
small gzipped JSON file and ``--restore FILE`` puts them back into mutants/: mutmut keeps the
result of every mutant whose function is unchanged, so a run on another machine (or after
mutants/ was removed) carries on where the saved one stopped instead of starting again.
``--not-caught`` prints only the names of the mutants not caught (``mutation.sh --recheck``).
"""

from __future__ import annotations

import gzip
import json
import sys
from collections import Counter
from pathlib import Path

from mutmut.stats import status_by_exit_code

CORE = Path("mutants/studio/core")
NOT_CAUGHT = ("survived", "no tests")
SAVED_FIELDS = ("exit_code_by_key", "hash_by_function_name")


def main(args: list[str]) -> None:
    """Print the table and write mutants/survivors.txt, or do what the one option says."""
    if args[:1] == ["--save"] and len(args) == 2:
        save(Path(args[1]))
    elif args[:1] == ["--restore"] and len(args) == 2:
        restore(Path(args[1]))
    elif args == ["--not-caught"]:
        print("\n".join(name for _, name in not_caught()))
    elif not args:
        report()
    else:
        sys.exit("usage: mutation_report.py [--not-caught | --save FILE | --restore FILE]")


def results() -> dict[str, dict]:
    """{path of the .meta file below mutants/: its JSON} for every core module."""
    return {str(meta.relative_to("mutants")): json.loads(meta.read_text())
            for meta in sorted(CORE.rglob("*.py.meta"))}


def not_caught() -> list[tuple[str, str]]:
    """(verdict, mutant name) of every mutant tested and not caught."""
    return [(verdict, name) for data in results().values()
            for name, code in data.get("exit_code_by_key", {}).items()
            if (verdict := status_by_exit_code[code]) in NOT_CAUGHT]


def report() -> None:
    """The table per module and overall; the survivors into mutants/survivors.txt."""
    rows: dict[str, Counter] = {}
    for path, data in results().items():
        module = path.removeprefix("studio/core/").removesuffix(".py.meta")
        rows[module] = Counter(status_by_exit_code[code]
                               for code in data.get("exit_code_by_key", {}).values())
    total: Counter = Counter()
    print(f"{'module':28} {'mutants':>7} {'killed':>7} {'timeout':>7} {'survived':>8} "
          f"{'no tests':>8} {'other':>6} {'not run':>7} {'score':>6}")
    for module, counts in rows.items():
        total.update(counts)
        print(line(module, counts))
    print(line("studio/core", total))
    survivors = [f"{verdict:9} {name}" for verdict, name in not_caught()]
    Path("mutants/survivors.txt").write_text("\n".join(survivors) + "\n")
    print(f"{len(survivors)} survivors listed in mutants/survivors.txt")


def line(name: str, c: Counter) -> str:
    """A table row; the score is (killed + timeout) / (mutants tested, skipped ones excluded)."""
    pending = c["not checked"]
    tested = sum(c.values()) - c["skipped"] - pending
    caught = c["killed"] + c["timeout"]
    other = tested - caught - c["survived"] - c["no tests"]
    score = f"{100 * caught / tested:5.1f}%" if tested else "   -  "
    return (f"{name:28} {sum(c.values()):7} {c['killed']:7} {c['timeout']:7} {c['survived']:8} "
            f"{c['no tests']:8} {other:6} {pending:7} {score}")


def save(path: Path) -> None:
    """The results in a few hundred kilobytes: per module its functions' hashes and its
    mutants' exit codes (mutmut's durations and type-check notes are left out)."""
    saved = {name: {field: data.get(field, {}) for field in SAVED_FIELDS}
             for name, data in results().items()}
    path.write_bytes(gzip.compress(json.dumps(saved, sort_keys=True).encode(), mtime=0))
    print(f"saved the results of {len(saved)} modules to {path}")


def restore(path: Path) -> None:
    """Saved results back into mutants/ for mutmut's next run to start from."""
    saved = json.loads(gzip.decompress(path.read_bytes()))
    for name, data in saved.items():
        meta = Path("mutants") / name
        meta.parent.mkdir(parents=True, exist_ok=True)
        meta.write_text(json.dumps({**data, "durations_by_key": {},
                                    "estimated_durations_by_key": {},
                                    "type_check_error_by_key": {}}))
    print(f"restored the results of {len(saved)} modules from {path}")


if __name__ == "__main__":
    main(sys.argv[1:])
