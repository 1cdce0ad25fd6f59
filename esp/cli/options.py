"""Checks of option values shared by the commands, run by click as the options are parsed.

Each one refuses a value with a :class:`click.BadParameter` that names the option, what was
expected and what was found; the command group turns it into one line,
``esp: error: Invalid value for '--unit': ...``, and exit code 2, before any file is read.

Every number an option takes goes through the one value check of esp
(:func:`esp.core.values.check` / :func:`esp.core.values.parse`): a number option has the
type :class:`Number` with its quantity's range (never click's bare ``float`` or
``FloatRange``, which take ``nan``, ``inf`` and ``1e308``), and the callbacks below check
with it too. ``tests/test_cli_numeric_options.py`` walks every command's options and holds
them to this.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any

import click

from esp.core.errors import DataError
from esp.core.units import (
    DISPLACEMENT_UNITS,
    MIN_SPACING_MM,
    POSITION_LIMIT_MM,
    canonical_unit,
    flush_tiny,
)
from esp.core.values import QUANTITIES, Quantity, ValueRefused, check, parse, shown

__all__ = [
    "ModalCommand",
    "decision_options",
    "Number",
    "finite_mm",
    "length_unit",
    "nonzero_mm",
    "positive_um",
    "unit",
]


class Number(click.ParamType):
    """A number option read by the one value check of esp (:func:`esp.core.values.parse`):
    decimal digits only (``1_000`` is refused as the files refuse ``3_0``), finite,
    within the range of ``quantity``, and at least ``smallest`` in size unless 0 is
    allowed; the refusal shows the text as given (``--displacement 1e-300`` is not shown
    as 0)."""

    name = "number"

    def __init__(self, quantity: str | Quantity, smallest: float = 0.0, what: str = ""):
        self.quantity = quantity
        self.smallest = smallest
        self.what = what

    def convert(
        self, value: Any, param: click.Parameter | None, ctx: click.Context | None
    ) -> float:
        if isinstance(value, float | int) and not isinstance(value, bool):
            text = None  # a default
        else:
            text = str(value)
        try:
            x = check(value, self.quantity) if text is None else parse(text, self.quantity)
        except ValueRefused as exc:
            self.fail(exc.message, param, ctx)
        if abs(x) < self.smallest:
            q = QUANTITIES[self.quantity] if isinstance(self.quantity, str) else self.quantity
            self.fail(
                f"expected {self.what}, at least {self.smallest:g} {q.unit} in size, "
                f"found {shown(value)}",
                param,
                ctx,
            )
        return flush_tiny(x)


def unit(ctx: click.Context, param: click.Parameter, value: str | None) -> str | None:
    """A unit esp knows (``um``, ``arcsec``, ...), in its canonical spelling."""
    if value is None:
        return None
    try:
        return canonical_unit(value)
    except DataError as exc:
        raise click.BadParameter(str(exc)) from None


def length_unit(ctx: click.Context, param: click.Parameter, value: str | None) -> str | None:
    """A unit of length for linear deviations (``um``, ``nm``, ``mm``, ``in``)."""
    u = unit(ctx, param, value)
    if u is not None and u not in DISPLACEMENT_UNITS:
        raise click.BadParameter(
            f"expected a unit of length ({', '.join(DISPLACEMENT_UNITS)}), found {value!r}"
        )
    return u


def _checked(value: Any, quantity: str | Quantity) -> float:
    """``value`` through the one value check; a refusal is a :class:`click.BadParameter`."""
    try:
        return check(value, quantity)
    except ValueRefused as exc:
        raise click.BadParameter(exc.message) from None


def finite_mm(ctx: click.Context, param: click.Parameter, value: float | None) -> float | None:
    """A position in mm within ±100 m (:data:`esp.core.units.POSITION_LIMIT_MM`)."""
    if value is None:
        return None
    limit = Quantity("a position", "mm", -POSITION_LIMIT_MM, POSITION_LIMIT_MM)
    return flush_tiny(_checked(value, limit))


def nonzero_mm(ctx: click.Context, param: click.Parameter, value: float | None) -> float | None:
    """A non-zero distance in mm, 1 µm to 100 m in size (:data:`esp.core.units.MIN_SPACING_MM`,
    :data:`esp.core.units.POSITION_LIMIT_MM`)."""
    value = finite_mm(ctx, param, value)
    if value is not None and abs(value) < MIN_SPACING_MM:
        raise click.BadParameter(
            f"expected a non-zero distance in mm, at least {MIN_SPACING_MM:g} mm in size, "
            f"found {shown(value)}"
        )
    return value


def positive_um(ctx: click.Context, param: click.Parameter, value: float | None) -> float | None:
    """A threshold in µm: above 0 and within the range of ``"threshold"``
    (:data:`esp.core.values.QUANTITIES`)."""
    return None if value is None else _checked(value, "threshold")


class ModalCommand(click.Command):
    """A command whose options belong to modes: which mode a command line selects is read
    from the options it gives (``mode_of``), and an option of another mode is refused in one
    line before the command runs, through click's own parsing step
    (:meth:`click.Command.parse_args`) rather than by checks in the command's body.

    ``modes`` maps an option's parameter name to the modes it belongs to; options not
    named belong to every mode. ``refusal(option, given_mode)`` words the message.
    """

    def __init__(
        self,
        *args: Any,
        mode_of: Callable[[Mapping[str, Any]], str],
        modes: Mapping[str, frozenset[str]],
        refusal: Callable[[str, str], str],
        **kwargs: Any,
    ) -> None:
        super().__init__(*args, **kwargs)
        self.mode_of = mode_of
        self.modes = modes
        self.refusal = refusal

    def parse_args(self, ctx: click.Context, args: list[str]) -> list[str]:
        rest = super().parse_args(ctx, args)
        given = {
            name: value
            for name, value in ctx.params.items()
            if ctx.get_parameter_source(name) == click.core.ParameterSource.COMMANDLINE
        }
        mode = self.mode_of(given)
        for param in self.params:
            name = param.name
            if name in given and name in self.modes and mode not in self.modes[name]:
                flag = param.opts[0] if isinstance(param, click.Option) else name
                raise click.UsageError(self.refusal(flag, mode), ctx)
        return rest


def decision_options(tolerance_help: str, rule_needs: str) -> Callable[[Any], Any]:
    """The options of a command that decides its figures against tolerances
    (:mod:`esp.core.conformity`): ``--tolerance FIG=UM`` (repeatable, ``tolerance_help``
    says which figures), ``--rule simple|guarded`` (``rule_needs``: what a guarded rule
    needs) and ``--guard F``, in that order."""
    from esp.config.tolerance import GUARD_FRACTION

    def wrap(f: Any) -> Any:
        f = click.option(
            "--guard",
            type=Number(GUARD_FRACTION),
            default=1.0,
            show_default=True,
            metavar="F",
            help="The guard band of --rule guarded as a fraction of U.",
        )(f)
        f = click.option(
            "--rule",
            type=click.Choice(["simple", "guarded"]),
            default="simple",
            show_default=True,
            help="Decision rule: simple acceptance, or guarded acceptance with guard band "
            f"w = GUARD·U (ISO 14253-1); guarded needs {rule_needs}.",
        )(f)
        return click.option(
            "--tolerance", "tolerances", multiple=True, metavar="FIG=UM", help=tolerance_help
        )(f)

    return wrap
