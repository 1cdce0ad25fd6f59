"""The one interface every compensation format implements (:class:`Format`), what a
format can hold (:class:`Capabilities`), its limits (:class:`Limits`) and the options of
all formats in one record (:class:`FormatSettings`).

A format module under :mod:`esp.compensation.formats` defines one or more
:class:`Format` objects in its module-level tuple ``FORMATS``; the registry
(:func:`esp.compensation.formats.registry`) finds them. Adding a format is one module and
its test module.

This module imports only numpy and the standard library.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from esp.compensation.model import CompensationSet

if TYPE_CHECKING:
    from esp.compensation.field import Fields
    from esp.compensation.predict import Prediction
    from esp.core.machine import Machine

__all__ = ["TABLE_KINDS", "Capabilities", "Format", "FormatSettings", "Limits"]

#: the kinds of table a format may hold (see :mod:`esp.compensation.model`):
#: ``lead`` an axis table of an axis over its own position, ``cross`` an axis table of an
#: axis over another's, ``plane`` a table over two masters, ``component`` the ISO 230-1
#: components themselves
TABLE_KINDS = ("lead", "cross", "plane", "component")


@dataclass(frozen=True)
class Capabilities:
    """What a format can hold.

    tables : the kinds of table it writes (:data:`TABLE_KINDS`)
    axes : the axes it corrects
    error_kinds : the error kinds (``linear``, ``straightness``, ``squareness``,
        ``angular``) its tables can hold
    bidirectional : its leadscrew tables hold one curve per direction of motion
    masters_per_axis : how many cross tables (each over another master axis) may correct
        one axis; their corrections add up
    rotary_modulo : it writes the angular positioning tables of a rotary table's axes
        (:class:`~esp.compensation.model.RotaryTable`), modulo over one turn
    """

    tables: frozenset[str]
    axes: tuple[str, ...] = ("X", "Y", "Z")
    error_kinds: frozenset[str] = frozenset({"linear"})
    bidirectional: bool = False
    masters_per_axis: int = 1
    rotary_modulo: bool = False

    @property
    def cross_terms(self) -> bool:
        """True when a table corrects one axis from another's position."""
        return bool(self.tables & {"cross", "plane"})


@dataclass(frozen=True)
class Limits:
    """A format's documented limits (None: none documented, or set by the user).

    points_per_table : the most points of one table
    tables : the most tables of the format
    plane_points : the most points of a plane table
    equidistant : the table points must lie at one spacing that divides the travel
    """

    points_per_table: int | None = None
    tables: int | None = None
    plane_points: int | None = None
    equidistant: bool = False


@dataclass(frozen=True)
class FormatSettings:
    """The options of the formats (each format reads those it uses).

    linuxcnc_type, linuxcnc_units : LinuxCNC ``COMP_FILE_TYPE`` and machine units
    axis_numbers : the controller's axis numbers by letter (ISG logical axes, Fanuc and
        Siemens axis indices)
    limits : table-size limits given by the user, by the format's limit name
    cross_sign : whether cross and plane tables whose sign the documentation leaves open
        hold the error or the correction
    max_records : ``vol_comp[i].max_records`` of an ISG start-up list
    machine_name : the machine's name, for headers
    options : the formats' open choices by name (``--format-option``,
        :attr:`Format.format_options`)
    """

    linuxcnc_type: int = 1
    linuxcnc_units: str = "mm"
    axis_numbers: Mapping[str, int] = field(default_factory=lambda: {"X": 1, "Y": 2, "Z": 3})
    limits: Mapping[str, int] = field(default_factory=dict)
    cross_sign: str = "error"
    max_records: int | None = None
    machine_name: str = ""
    options: Mapping[str, str] = field(default_factory=dict)

    def option(self, name: str, default: str) -> str:
        """The value of the format option ``name`` (``default`` when not given)."""
        return str(self.options.get(name, default))

    def number(self, axis: str) -> int:
        """The controller's number of ``axis`` (X=1, Y=2, Z=3 unless given)."""
        return int({"X": 1, "Y": 2, "Z": 3, **self.axis_numbers}[axis])


class Format(ABC):
    """One controller format: what it holds, its limits, how it is written, read back and
    applied by the controller.

    Subclasses set the class attributes and implement :meth:`write`, :meth:`read` and
    :meth:`resolution_um`; :meth:`predict` applies the tables as
    :func:`esp.compensation.predict.predict` does (axis tables linear between their points,
    ends held; plane tables bilinear; component tables through the machine's model), which
    a format whose controller applies its tables otherwise overrides.
    """

    #: the ``--format`` name
    name: str = ""
    #: one line for ``--help`` and the reports
    description: str = ""
    #: how the files are loaded into the controller (one sentence for the report)
    load_words: str = ""
    #: the controller setting that must allow :meth:`records` records
    records_setting: str = ""
    #: the choices the documentation leaves open (``--format-option NAME=VALUE``): name ->
    #: (allowed values, the first the default; or ``("<number>", default)`` for a number)
    format_options: Mapping[str, tuple[str, ...]] = {}
    #: the limits the user may set (``--max-points NAME=N``), name -> default
    limit_defaults: Mapping[str, int] = {}
    #: the controller's tables are zero at its reference position (incremental data): read
    #: back, a table equals the written one less its forward value at the first point
    zero_at_reference: bool = False
    #: the position of the format in ``--format`` choices
    order: int = 100
    capabilities: Capabilities = Capabilities(frozenset())

    def limits(self, settings: FormatSettings) -> Limits:
        """The limits that apply with ``settings`` (default: none)."""
        return Limits()

    @abstractmethod
    def write(self, cset: CompensationSet, settings: FormatSettings) -> dict[str, str]:
        """File name -> text of every file; :class:`~esp.core.errors.DataError` for a
        table beyond the format's limits."""

    @abstractmethod
    def read(self, files: Mapping[str, str], settings: FormatSettings) -> CompensationSet:
        """The tables the files hold, by a reader of the format's own documentation;
        :class:`~esp.core.errors.ParseError` naming the file and line otherwise."""

    @abstractmethod
    def resolution_um(self, settings: FormatSettings) -> float:
        """The smallest step of a written correction or error (µm)."""

    def records(self, cset: CompensationSet) -> int | None:
        """The number of records a controller setting must allow (None: no such
        setting)."""
        return None

    def predict(
        self,
        machine: Machine,
        applied: CompensationSet,
        settings: FormatSettings,
        fields: Fields | None = None,
    ) -> Prediction:
        """The residual with ``applied`` (the tables as read back) applied as the
        controller applies them."""
        from esp.compensation.predict import predict

        return predict(machine, applied, self.resolution_um(settings), fields)
