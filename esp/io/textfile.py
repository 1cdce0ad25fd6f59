"""Read a measurement file as text, whatever its encoding and line ends.

Instrument software writes its files with CRLF or LF line ends, sometimes with a UTF-8
byte-order mark, and machine or operator text in a legacy Windows code page. This module
turns such a file into one ``str`` with ``\\n`` line ends, or raises :class:`ParseError`
with a one-line reason when the file is not text at all (a folder, an empty file, a
spreadsheet or other binary file).

Decoding order: a UTF-16 byte-order mark selects UTF-16; otherwise UTF-8 (a leading BOM is
removed), then Windows-1252, then Latin-1, the first that decodes without error.
"""

from __future__ import annotations

import os
import re
import stat
from collections.abc import Iterator
from pathlib import Path

from esp.core.errors import ParseError

__all__ = [
    "DATA_FILE_MAX_BYTES",
    "decode_bytes",
    "normalise_newlines",
    "read_regular_bytes",
    "read_text",
    "read_utf8",
    "iter_lines",
    "split_lines",
]

#: the largest data file esp reads (a Laser10 file of thousands of targets is < 1 MB)
DATA_FILE_MAX_BYTES = 64 * 1024 * 1024

_UTF8_BOM = b"\xef\xbb\xbf"
_UTF16_BOMS = (b"\xff\xfe", b"\xfe\xff")
#: above this share of control characters, a decoded file is taken as binary
_MAX_CONTROL_SHARE = 0.05
_ALLOWED_CONTROLS = frozenset("\t\n\r\f\v")
_CONTROL_RE = re.compile("[\x00-\x08\x0e-\x1f\x7f-\x9f]")


def normalise_newlines(text: str) -> str:
    """Return ``text`` with CRLF and lone CR turned into LF and a leading BOM removed."""
    if text.startswith("\ufeff"):
        text = text[1:]
    return text.replace("\r\n", "\n").replace("\r", "\n")


def split_lines(text: str) -> list[str]:
    """Split ``text`` into lines at LF, CRLF or CR only.

    Unlike :meth:`str.splitlines`, form feeds and other Unicode separators do not end a
    line, so line numbers agree with what a text editor shows. Line ``i`` of the file is
    element ``i - 1``.
    """
    return normalise_newlines(text).split("\n")


def iter_lines(text: str) -> Iterator[str]:
    """The lines of ``text`` as :func:`split_lines` gives them, one at a time: reading a
    file line by line keeps only the lines it needs, not a list of every line (a 64 MiB
    file of empty lines would be 64 million strings, several GB)."""
    text = normalise_newlines(text)
    start = 0
    while True:
        end = text.find("\n", start)
        if end < 0:
            yield text[start:]
            return
        yield text[start:end]
        start = end + 1


def _line_of_offset(data: bytes, offset: int) -> int:
    return data.count(b"\n", 0, offset) + 1


def _control_count(text: str) -> int:
    """The number of control characters other than :data:`_ALLOWED_CONTROLS` (C0 and DEL
    and C1), counted by the regular-expression engine: a Python loop over every character
    took half a minute for a 48 MiB file."""
    return _CONTROL_RE.subn("", text)[1]


def decode_bytes(data: bytes, path: str | Path | None = None) -> str:
    """Decode the bytes of a text data file.

    Parameters
    ----------
    data : the whole file
    path : used in error messages only

    Returns
    -------
    str
        The text, without a byte-order mark, with ``\\n`` line ends.

    Raises
    ------
    ParseError
        The file is empty (or blank), holds NUL bytes or mostly non-printable characters,
        or starts with a UTF-16 byte-order mark but is not valid UTF-16.
    """
    if data.startswith(_UTF16_BOMS):
        try:
            text = data.decode("utf-16")
        except UnicodeDecodeError as exc:
            raise ParseError(
                path, None, f"expected UTF-16 text after its byte-order mark, found {exc.reason}"
            ) from None
    else:
        nul = data.find(b"\x00")
        if nul >= 0:
            raise ParseError(
                path,
                _line_of_offset(data, nul),
                f"expected a text file, found binary data (a NUL byte at offset {nul})",
            )
        body = data[len(_UTF8_BOM) :] if data.startswith(_UTF8_BOM) else data
        for encoding in ("utf-8", "cp1252", "latin-1"):
            try:
                text = body.decode(encoding)
                break
            except UnicodeDecodeError:
                continue
        else:  # pragma: no cover - latin-1 decodes every byte
            raise ParseError(
                path, None, "expected text in UTF-8 or Latin-1, found undecodable bytes"
            )
    text = normalise_newlines(text)
    if not text.strip():
        raise ParseError(path, None, "expected a data file, found an empty file")
    controls = _control_count(text)
    if controls > _MAX_CONTROL_SHARE * len(text):
        raise ParseError(
            path,
            None,
            f"expected a text file, found binary data "
            f"({controls} of {len(text)} characters are not printable)",
        )
    return text


def _size(n: int) -> str:
    """A file size for a message: bytes below 1 MiB, else MiB to one decimal."""
    mib = 1024 * 1024
    if n < mib:
        return f"{n} bytes"
    return f"{n // mib} MiB" if n % mib == 0 else f"{n / mib:.1f} MiB"


def read_regular_bytes(path: str | Path, max_bytes: int, what: str = "data file") -> bytes:
    """The bytes of a regular file of at most ``max_bytes``.

    Anything else is refused before a byte is read: a missing path, a folder, a device,
    a FIFO or socket (``/dev/zero``, a named pipe: reading them would never end), an
    unreadable file, or a file larger than ``max_bytes``.

    Raises
    ------
    ParseError
        With the path and a one-line reason.
    """
    p = Path(path)
    try:
        info = os.stat(p)
    except FileNotFoundError:
        raise ParseError(path, None, f"expected a {what}, found no such file") from None
    except OSError as exc:
        reason = exc.strerror or str(exc)
        raise ParseError(path, None, f"expected a readable {what}, found: {reason}") from None
    if stat.S_ISDIR(info.st_mode):
        raise ParseError(path, None, f"is a directory, expected a {what}")
    if not stat.S_ISREG(info.st_mode):
        raise ParseError(path, None, f"expected a regular {what}, found a device, pipe or socket")
    if info.st_size > max_bytes:
        raise ParseError(
            path,
            None,
            f"expected a {what} of at most {_size(max_bytes)}, found {_size(info.st_size)}",
        )
    try:
        with open(p, "rb") as fh:
            data = fh.read(max_bytes + 1)
    except PermissionError:
        raise ParseError(
            path, None, f"expected a readable {what}, found permission denied"
        ) from None
    except OSError as exc:
        reason = exc.strerror or str(exc)
        raise ParseError(path, None, f"expected a readable {what}, found: {reason}") from None
    if len(data) > max_bytes:  # grew while being read
        raise ParseError(path, None, f"expected a {what} of at most {max_bytes} bytes")
    return data


def read_utf8(path: str | Path, max_bytes: int, what: str) -> str:
    """A small UTF-8 file esp is given besides the measurement data (error values, curves,
    measured differences): :func:`read_regular_bytes`, then UTF-8 (a byte-order mark is
    allowed) with the line of the first byte that is not."""
    data = read_regular_bytes(path, max_bytes, what)
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        line = _line_of_offset(data, exc.start)
        raise ParseError(
            path, line, f"expected UTF-8 text, found byte {data[exc.start]:#04x}"
        ) from None


def read_text(path: str | Path) -> str:
    """Read a data file as text.

    Parameters
    ----------
    path : the file

    Returns
    -------
    str
        The decoded text with ``\\n`` line ends and no byte-order mark (see
        :func:`decode_bytes`).

    Raises
    ------
    ParseError
        The path is not a regular file of at most :data:`DATA_FILE_MAX_BYTES`, cannot be
        read, or is not text.
    """
    return decode_bytes(read_regular_bytes(path, DATA_FILE_MAX_BYTES), path)
