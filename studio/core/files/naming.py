"""Names: new ones that do not clash with existing ones ("forehead", "forehead 2", …), and
names taken from a user's file made safe to show on one line of a terminal."""

from __future__ import annotations

import unicodedata
from collections.abc import Iterable

# The longest name shown: a file may hold a megabyte of name, and a message is one line.
SHOWN_CHARACTERS = 120


def unique_name(base: str, taken: Iterable[str]) -> str:
    names = set(taken)
    if base not in names:
        return base
    n = 2
    while f"{base} {n}" in names:
        n += 1
    return f"{base} {n}"


def _escape(char: str) -> str:
    code = ord(char)
    return f"\\x{code:02x}" if code < 0x100 else f"\\u{code:04x}" if code < 0x10000 else \
        f"\\U{code:08x}"


def shown(text: object, limit: int = SHOWN_CHARACTERS) -> str:
    """``text`` as it can be printed on one line: control and format characters (newlines,
    ANSI escapes, bidirectional overrides, line and paragraph separators, lone surrogates)
    written as Python escapes, and anything past ``limit`` characters cut to "…".

    Why: names, URIs and extension names come from the user's file. Printed raw, a newline
    makes a second line that can pose as a traceback, and an ANSI escape can clear or recolour
    the terminal; the studio's rule is one plain line per message.
    """
    text = str(text)
    cut = len(text) > limit
    text = text[:limit]
    if text.isprintable():  # the common case, in C: nothing to escape
        return text + "…" * cut
    out = "".join(_escape(c) if unicodedata.category(c) in ("Cc", "Cf", "Cs", "Co", "Cn",
                                                              "Zl", "Zp") else c for c in text)
    return out + "…" * cut


def shown_list(names: Iterable[object], limit: int = 40) -> str:
    """Names joined with commas, each :func:`shown`, at most ``limit`` of them (a file can name
    a million nodes) followed by how many more there are."""
    items = list(names)
    text = ", ".join(shown(n) for n in items[:limit])
    return text + (f" and {len(items) - limit:,} more" if len(items) > limit else "")
