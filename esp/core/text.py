"""Text that reaches one line of output: user strings shown escaped, and the "did you
mean" hint of a message refusing an unknown word.

A machine name, a file name or a component source may hold a line break or another control
character, or a bidirectional control (a right-to-left override) that reorders what a
terminal or a Markdown viewer shows after it. Everything esp writes as one line -- a
message, a row of a table, a title, a cell of ``summary.md`` -- passes user text through
:func:`one_line`, so that it can neither split the line nor reorder it. Standard library
only: the command line uses it before anything else is loaded.
"""

from __future__ import annotations

from collections.abc import Iterable

__all__ = [
    "BIDI_CONTROLS",
    "NAME_MAX_CHARS",
    "TEXT_MAX_CHARS",
    "article",
    "closest",
    "did_you_mean",
    "one_line",
    "too_long",
]

#: the longest name or short field a user gives (a machine's or chain's name, serial,
#: location, operator, a USER-TEXT key): every report title, footer and table row shows it,
#: and drawing a long unbroken line costs time that grows faster than its length
NAME_MAX_CHARS = 200
#: the longest free text (a description, a reference, a USER-TEXT value of a data file)
TEXT_MAX_CHARS = 2000

#: the bidirectional formatting characters of Unicode (UAX #9, 2.1-2.6): the embeddings and
#: overrides U+202A-U+202E, the isolates U+2066-U+2069, the marks U+200E, U+200F and the
#: Arabic letter mark U+061C; shown escaped (``\u202e``) wherever user text is written
BIDI_CONTROLS = frozenset(
    [chr(c) for c in range(0x202A, 0x202F)]
    + [chr(c) for c in range(0x2066, 0x206A)]
    + ["\u200e", "\u200f", "\u061c"]
)


def one_line(text: object) -> str:
    """``text`` on one line: line breaks, other control characters and the bidirectional
    controls (:data:`BIDI_CONTROLS`) shown escaped (``\\n``, ``\\r``, ``\\x1b``,
    ``\\u202e``; a tab becomes a space), so that user text -- a machine or file name --
    can neither split nor reorder a row of a table, a title or a message."""
    text = str(text)
    if text.isprintable():
        return text
    out = []
    for ch in text:
        code = ord(ch)
        if ch == "\n":
            out.append("\\n")
        elif ch == "\r":
            out.append("\\r")
        elif ch == "\t":
            out.append(" ")
        elif (
            code < 32
            or code == 127
            or 0x80 <= code < 0xA0
            or ch in "\u2028\u2029"
            or ch in BIDI_CONTROLS
        ):
            out.append(f"\\x{code:02x}" if code < 256 else f"\\u{code:04x}")
        else:
            out.append(ch)
    return "".join(out)


def too_long(text: str | int, limit: int) -> str | None:
    """The end of a message refusing ``text`` (or a length) longer than ``limit`` characters
    (``"expected at most 200 characters, found 2048"``), or None when it fits; the caller
    names the key or the file and line."""
    length = text if isinstance(text, int) else len(text)
    if length <= limit:
        return None
    return f"expected at most {limit} characters, found {length}"


def closest(word: object, options: Iterable[str]) -> str | None:
    """The option ``word`` most likely meant: one equal to it but for case, else the
    closest by :func:`difflib.get_close_matches` (ignoring case), else ``None``."""
    import difflib  # only when a message needs a hint: the command line starts without it

    options = list(options)
    for option in options:
        if option.lower() == str(word).lower():
            return option
    lowered = {o.lower(): o for o in options}
    close = difflib.get_close_matches(str(word).lower(), list(lowered), n=1, cutoff=0.6)
    return lowered[close[0]] if close else None


def did_you_mean(word: object, options: Iterable[str]) -> str:
    """``"; did you mean 'X'?"`` with :func:`closest`, or ``""`` when nothing is close: the
    tail of a message refusing an unknown key or name."""
    hint = closest(word, options)
    return f"; did you mean {hint!r}?" if hint is not None else ""


def article(word: str) -> str:
    """``word`` with its indefinite article: "a parameter", "an error"."""
    return f"an {word}" if word[:1] in "aeiou" else f"a {word}"
