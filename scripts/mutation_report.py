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
``--markdown`` prints the table per package as the README shows it.

The survivors go to docs/mutation-survivors.txt, grouped by module, each with the line mutmut
changed (``mutmut show NAME`` gives the whole diff): the list the README points to, kept with
the code so a change that kills or adds survivors shows in review.
"""

from __future__ import annotations

import ast
import difflib
import gzip
import json
import sys
from collections import Counter
from pathlib import Path

from mutmut.stats import status_by_exit_code

CORE = Path("mutants/studio/core")
SURVIVORS = Path("docs/mutation-survivors.txt")
NOT_CAUGHT = ("survived", "no tests")
SAVED_FIELDS = ("exit_code_by_key", "hash_by_function_name")


def main(args: list[str]) -> None:
    """Print the table and write SURVIVORS, or do what the one option says."""
    if args[:1] == ["--save"] and len(args) == 2:
        save(Path(args[1]))
    elif args[:1] == ["--restore"] and len(args) == 2:
        restore(Path(args[1]))
    elif args == ["--not-caught"]:
        print("\n".join(name for _, name in not_caught()))
    elif args == ["--markdown"]:
        markdown()
    elif not args:
        report()
    else:
        sys.exit("usage: mutation_report.py [--not-caught | --markdown | --save FILE | "
                 "--restore FILE]")


def results() -> dict[str, dict]:
    """{path of the .meta file below mutants/: its JSON} for every core module."""
    return {str(meta.relative_to("mutants")): json.loads(meta.read_text())
            for meta in sorted(CORE.rglob("*.py.meta"))}


def not_caught() -> list[tuple[str, str]]:
    """(verdict, mutant name) of every mutant tested and not caught."""
    return [(verdict, name) for data in results().values()
            for name, code in data.get("exit_code_by_key", {}).items()
            if (verdict := status_by_exit_code[code]) in NOT_CAUGHT]


def counts_by_module() -> dict[str, Counter]:
    """{module below studio/core: Counter of verdicts}."""
    return {path.removeprefix("studio/core/").removesuffix(".py.meta"):
            Counter(status_by_exit_code[code] for code in data.get("exit_code_by_key", {}).values())
            for path, data in results().items()}


def report() -> None:
    """The table per module, per package and overall; the survivors into SURVIVORS."""
    rows = counts_by_module()
    packages: dict[str, Counter] = {}
    total: Counter = Counter()
    print(f"{'module':28} {'mutants':>7} {'killed':>7} {'timeout':>7} {'survived':>8} "
          f"{'no tests':>8} {'other':>6} {'not run':>7} {'score':>6}")
    for module, counts in rows.items():
        total.update(counts)
        packages.setdefault(module.split("/")[0], Counter()).update(counts)
        print(line(module, counts))
    for package, counts in packages.items():
        print(line(f"{package}/", counts))
    print(line("studio/core", total))
    write_survivors(SURVIVORS)
    print(f"{len(not_caught())} survivors listed in {SURVIVORS}")


def markdown() -> None:
    """The README's table: per package, then the whole of studio/core."""
    packages: dict[str, Counter] = {}
    for module, counts in counts_by_module().items():
        packages.setdefault(module.split("/")[0], Counter()).update(counts)
    print("| package | mutants | run | caught | not caught | score |")
    print("|---|---|---|---|---|---|")
    total: Counter = Counter()
    for package, counts in packages.items():
        total.update(counts)
        print(markdown_row(package, counts))
    print(markdown_row("**studio/core**", total, bold=True))


def markdown_row(name: str, c: Counter, bold: bool = False) -> str:
    tested = sum(c.values()) - c["skipped"] - c["not checked"]
    caught = c["killed"] + c["timeout"]
    cells = [f"{sum(c.values()):,}", f"{tested:,}", f"{caught:,}", f"{tested - caught:,}",
             f"{100 * caught / tested:.1f} %" if tested else "-"]
    cells = [cell.replace(",", "\u2009") for cell in cells]  # thin spaces, as the README writes
    if bold:
        cells = [f"**{cell}**" for cell in cells]
    return f"| {name} | " + " | ".join(cells) + " |"


def write_survivors(path: Path) -> None:
    """Each module's survivors with the line mutmut changed: ``- old`` then ``+ new``."""
    by_module: dict[str, list[tuple[str, str]]] = {}
    for verdict, name in not_caught():
        module, function = name.rsplit(".", 1)
        by_module.setdefault(module, []).append((verdict, function))
    out = [f"# Mutants of studio/core no test catches ({sum(map(len, by_module.values()))}), "
           "written by scripts/mutation_report.py.",
           "# `mutmut show NAME` (NAME = module.function) gives a mutant's whole diff.", ""]
    for module in sorted(by_module):
        functions = mutated_functions(module)
        out.append(f"## {module}")
        for verdict, function in by_module[module]:
            change = changed_lines(functions, function)
            out.append(f"{function}  [{verdict}]  {change}" if change else
                       f"{function}  [{verdict}]")
        out.append("")
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text("\n".join(out))


def mutated_functions(module: str) -> dict[str, list[str]]:
    """{function name: its source lines} of the module's mutated copy in mutants/."""
    source = (Path("mutants") / Path(*module.split("."))).with_suffix(".py").read_text()
    lines = source.splitlines()
    return {node.name: lines[node.lineno - 1:node.end_lineno]
            for node in ast.walk(ast.parse(source)) if isinstance(node, ast.FunctionDef)}


def changed_lines(functions: dict[str, list[str]], mutant: str) -> str:
    """``- old | + new``: the lines a mutant changed (its signature left out), shortened."""
    original = functions.get(mutant.split("__mutmut_")[0] + "__mutmut_orig")
    mutated = functions.get(mutant)
    if original is None or mutated is None:
        return ""
    diff = [d[0] + " " + d[1:].strip()
            for d in difflib.unified_diff(original[1:], mutated[1:], lineterm="", n=0)
            if d[:1] in "+-" and d[:3] not in ("+++", "---")]
    text = " | ".join(diff)
    return text if len(text) <= 240 else text[:237] + "..."


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
