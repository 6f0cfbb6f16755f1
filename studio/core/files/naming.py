"""Names for new things that do not clash with existing ones ("forehead", "forehead 2", …)."""

from __future__ import annotations

from collections.abc import Iterable


def unique_name(base: str, taken: Iterable[str]) -> str:
    names = set(taken)
    if base not in names:
        return base
    n = 2
    while f"{base} {n}" in names:
        n += 1
    return f"{base} {n}"
