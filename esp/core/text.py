"""Text that reaches one line of output: user strings shown escaped, and the "did you
mean" hint of a message refusing an unknown word.

A machine name, a file name or a component source may hold a line break or another control
character. Everything esp writes as one line -- a message, a row of a table, a title --
passes user text through :func:`one_line`, so that it cannot split the line. Standard
library only: the command line uses it before anything else is loaded.
"""

from __future__ import annotations

from collections.abc import Iterable

__all__ = ["article", "closest", "did_you_mean", "one_line"]


def one_line(text: object) -> str:
    """``text`` on one line: line breaks and other control characters shown escaped
    (``\\n``, ``\\r``, ``\\x1b``; a tab becomes a space), so that user text -- a machine or
    file name -- cannot split a row of a table, a title or a message."""
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
        elif code < 32 or code == 127 or 0x80 <= code < 0xA0 or ch in "\u2028\u2029":
            out.append(f"\\x{code:02x}" if code < 256 else f"\\u{code:04x}")
        else:
            out.append(ch)
    return "".join(out)


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
