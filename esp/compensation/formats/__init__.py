"""The registry of compensation formats.

Every module of this package (other than :mod:`~esp.compensation.formats.base`) is one
controller's format: its writer, an independent reader written from the vendor's
documentation (cited in ``docs/compensation.md``) and a module-level tuple ``FORMATS`` of
:class:`~esp.compensation.formats.base.Format` objects. :func:`registry` finds them, so
adding a format is one module (and its test module).

One entry point per direction for any format by name: :func:`write_files` (a
:class:`~esp.compensation.model.CompensationSet` to the files of ``cset.format``) and
:func:`read_files` (the files back to a set), with the options of all formats in one
:class:`FormatSettings`.

This module imports only numpy and the standard library.
"""

from __future__ import annotations

import functools
import importlib
import pkgutil
from collections.abc import Mapping

from esp.compensation.formats.base import Capabilities, Format, FormatSettings, Limits
from esp.compensation.model import CompensationSet
from esp.core.errors import DataError

__all__ = [
    "Capabilities",
    "Format",
    "FormatSettings",
    "Limits",
    "check_options",
    "get",
    "limit_names",
    "names",
    "option_choices",
    "read_files",
    "registry",
    "resolution_um",
    "write_files",
]


@functools.cache
def registry() -> Mapping[str, Format]:
    """Format name -> format, over every module of this package, in the order of
    ``--format`` choices (each format's ``order``, then its name)."""
    found: list[Format] = []
    for info in pkgutil.iter_modules(__path__):
        if info.name.startswith("_") or info.name == "base":
            continue
        module = importlib.import_module(f"{__name__}.{info.name}")
        found.extend(getattr(module, "FORMATS", ()))
    out: dict[str, Format] = {}
    for fmt in sorted(found, key=lambda f: (f.order, f.name)):
        if fmt.name in out:
            raise RuntimeError(f"two compensation formats are named {fmt.name!r}")
        out[fmt.name] = fmt
    return out


def names() -> tuple[str, ...]:
    """The format names, in the order of ``--format`` choices."""
    return tuple(registry())


def limit_names() -> tuple[str, ...]:
    """The names of every limit a format lets the user set (``--max-points``)."""
    return tuple(dict.fromkeys(k for f in registry().values() for k in f.limit_defaults))


def option_choices() -> dict[str, tuple[str, ...]]:
    """Every format option by name -> its choices (``("<number>", default)`` for a
    number), over the registry."""
    out: dict[str, tuple[str, ...]] = {}
    for f in registry().values():
        out.update(f.format_options)
    return out


def check_options(options: Mapping[str, str]) -> dict[str, str]:
    """The format options checked against the choices the formats declare; DataError
    naming ``--format-option`` otherwise."""
    known = option_choices()
    out = {}
    for name, value in options.items():
        if name not in known:
            raise DataError(
                f"--format-option: expected a NAME of {', '.join(sorted(known))}, found {name!r}"
            )
        choices = known[name]
        if choices[0] == "<number>":
            try:
                number = float(value)
            except ValueError:
                number = float("nan")
            if not (number > 0 and number < 1e6):
                raise DataError(
                    f"--format-option {name}: expected a positive number, found {value!r}"
                )
        elif value not in choices:
            raise DataError(
                f"--format-option {name}: expected one of {', '.join(choices)}, found {value!r}"
            )
        out[name] = value
    return out


def get(name: str) -> Format:
    """The format called ``name``; :class:`DataError` naming the choices otherwise."""
    formats = registry()
    if name not in formats:
        raise DataError(f"unknown format {name!r}; expected one of {', '.join(formats)}")
    return formats[name]


def write_files(cset: CompensationSet, settings: FormatSettings | None = None) -> dict[str, str]:
    """File name -> text of every file of ``cset.format``."""
    return get(cset.format).write(cset, settings or FormatSettings())


def read_files(
    fmt: str, files: Mapping[str, str], settings: FormatSettings | None = None
) -> CompensationSet:
    """The set the files of ``fmt`` hold, by the format's own reader."""
    return get(fmt).read(files, settings or FormatSettings())


def resolution_um(fmt: str, settings: FormatSettings | None = None) -> float:
    """The smallest step of a written correction or displacement error (µm)."""
    return get(fmt).resolution_um(settings or FormatSettings())
