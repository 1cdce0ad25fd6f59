"""``SOURCE_DATE_EPOCH``, the date of a reproducible build
(https://reproducible-builds.org/specs/source-date-epoch/), checked once for every command
before any work: the date printed on a report follows it, and matplotlib's PDF writer reads
it too (and fails deep inside on a value such as ``" "``).

This module imports only the standard library.
"""

from __future__ import annotations

import datetime as _dt
import os
import re
from collections.abc import Mapping

from esp.core.errors import DataError
from esp.core.text import one_line

__all__ = ["SOURCE_DATE_EPOCH_MAX", "report_date", "source_date_epoch"]

#: the largest SOURCE_DATE_EPOCH: 9999-12-31T23:59:59Z
SOURCE_DATE_EPOCH_MAX = 253_402_300_799


def source_date_epoch(environ: Mapping[str, str] | None = None) -> int | None:
    """``SOURCE_DATE_EPOCH`` (seconds since 1970-01-01 UTC) when it is set, else None.

    Raises :class:`~esp.core.errors.DataError` when it is set to anything but a whole number
    from 0 to :data:`SOURCE_DATE_EPOCH_MAX` (the end of the year 9999), spaces around it
    allowed: a reproducible build with a wrong date must not pass unnoticed, and the PDF
    writer reads the variable too. An empty value counts as not set; a value of spaces
    only is refused (the PDF writer would fail on it).
    """
    env = os.environ if environ is None else environ
    raw = env.get("SOURCE_DATE_EPOCH")
    if raw is None or raw == "":
        return None
    text = raw.strip()
    if not re.fullmatch(r"[0-9]{1,20}", text) or int(text) > SOURCE_DATE_EPOCH_MAX:
        raise DataError(
            f"SOURCE_DATE_EPOCH: expected a whole number of seconds since 1970-01-01 UTC "
            f"from 0 to {SOURCE_DATE_EPOCH_MAX} (the end of 9999), found {one_line(raw)!r}; "
            "set it to such a number or unset it"
        )
    return int(text)


def report_date(environ: Mapping[str, str] | None = None) -> str:
    """The date printed on a report, ISO ``YYYY-MM-DD``: from ``SOURCE_DATE_EPOCH`` (UTC)
    when set, so builds can be reproduced; else today. A malformed value is refused
    (:func:`source_date_epoch`)."""
    epoch = source_date_epoch(environ)
    if epoch is None:
        return _dt.date.today().isoformat()
    return _dt.datetime.fromtimestamp(epoch, tz=_dt.UTC).date().isoformat()
