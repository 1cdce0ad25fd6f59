"""The ESP synthesis equations of Longstaff (2002), chapter 3, as tables of terms.

Nine equation sets: three machine configurations (wBMTt, BwMTt, BMwTt) times three
situations -- at the measurement centre point (eq. 3.1-3.3), at the tool centre point of an
uncompensated machine or one compensated at the TCP (eq. 3.10-3.12), and at the TCP of a
machine compensated at the MCP, with residual angles Φ and mechanical angles γ
(eq. 3.14-3.16). The thesis prints the configurations as tBMT, BtMT and BMtT in these
equations; they are wBMTt, BwMTt and BMwTt of section 3.02.

Each table is transcribed term by term in the order printed. Two features of the print
are kept deliberately: eq. 3.1 and 3.2 are identical (so are 3.10/3.11 in their MCP part),
and the straightness symbol of eq. 3.14 reads "strl" (a misprint of "strt"; it is the same
component). The five evaluation cases of section 3.10 choose among the sets
(:func:`equation_set`).
"""

from __future__ import annotations

from dataclasses import dataclass

from esp.core.models.terms import Term, parse_terms

__all__ = ["CASES", "EquationSet", "equation_set", "evaluation_case"]


def _set(source: str, B: str, M: str, T: str) -> tuple[Term, ...]:
    return parse_terms("B", B, source) + parse_terms("M", M, source) + parse_terms("T", T, source)


# ---- eq. 3.1-3.3: at the MCP ------------------------------------------------------------

_EQ_3_1 = dict(
    B="+B.lin +M.str(B) +T.str(B) +phi_M(B)*T +phi_M(M)*T +phi_T(B)*M +sqr(BT)*T +sqr(BM)*M",
    M="+M.lin +B.str(M) +T.str(M) +phi_B(B)*T +phi_B(M)*T +sqr(MT)*T",
    T="+T.lin +B.str(T) +M.str(T) -phi_B(B)*M",
)
# eq. 3.2 is printed identical to eq. 3.1
_EQ_3_2 = dict(_EQ_3_1)
_EQ_3_3 = dict(
    B="+B.lin +M.str(B) +T.str(B) +phi_M(B)*T +phi_M(M)*T +sqr(BT)*T +sqr(BM)*M",
    M="+M.lin +B.str(M) +T.str(M) +phi_B(B)*T +phi_B(M)*T +phi_T(M)*B +sqr(MT)*T",
    T="+T.lin +B.str(T) +M.str(T) -phi_M(M)*B",
)

# ---- eq. 3.10-3.12: at the TCP, tool offset (B_o, M_o, T_o) ------------------------------

_EQ_3_10 = dict(
    B="+B.lin +M.str(B) +T.str(B) +phi_M(B)*(T+To) +phi_M(M)*(T+To) +phi_T(B)*(M+Mo)"
    " +phi_T(M)*Mo +phi_T(T)*Mo -phi_M(T)*To +sqr(BT)*T +sqr(BM)*M",
    M="+M.lin +B.str(M) +T.str(M) +phi_B(B)*(T+To) +phi_B(M)*(T+To) -phi_T(B)*Bo"
    " -phi_T(M)*Bo -phi_T(T)*Bo -phi_B(T)*To +sqr(MT)*T",
    T="+T.lin +B.str(T) +M.str(T) -phi_B(B)*(M+Mo) -phi_M(B)*Bo -phi_M(M)*Bo +phi_M(T)*Bo"
    " -phi_B(M)*Mo +phi_B(T)*Mo",
)
_EQ_3_11 = dict(
    B="+B.lin +M.str(B) +T.str(B) +phi_M(B)*(T+To) +phi_M(M)*(T+To) +phi_T(B)*(M+Mo)"
    " +phi_T(M)*Mo +phi_T(T)*Mo +phi_M(T)*To +sqr(BT)*T +sqr(BM)*M",
    M="+M.lin +B.str(M) +T.str(M) +phi_B(B)*(T+To) +phi_B(M)*(T+To) +phi_B(T)*To"
    " -phi_T(M)*Bo -phi_T(T)*Bo +sqr(MT)*T",
    T="+T.lin +B.str(T) +M.str(T) -phi_B(B)*(M+Mo) -phi_B(T)*Mo -phi_B(M)*Mo -phi_M(M)*Bo"
    " -phi_M(T)*Bo",
)
_EQ_3_12 = dict(
    B="+B.lin +M.str(B) +T.str(B) +phi_M(B)*(T+To) +phi_M(M)*(T+To) +phi_T(M)*Mo"
    " +phi_T(B)*Mo +phi_T(T)*Mo -phi_M(T)*To +sqr(BT)*T +sqr(BM)*M",
    M="+M.lin +B.str(M) +T.str(M) +phi_B(B)*(T+To) +phi_B(M)*(T+To) +phi_T(M)*(B-Bo)"
    " -phi_B(T)*To -phi_T(B)*Bo -phi_T(T)*Bo +sqr(MT)*T",
    T="+T.lin +B.str(T) +M.str(T) -phi_M(M)*(B-Bo) +phi_B(M)*Mo +phi_B(B)*Mo -phi_B(T)*Mo"
    " +phi_M(B)*Bo -phi_M(T)*Bo",
)

# ---- eq. 3.14-3.16: TCP of a machine compensated at the MCP (Φ residual, γ mechanical) --

_EQ_3_14 = dict(
    B="+B.lin +M.str(B) +T.str(B) +phi_M(B)*T +gamma_M(B)*To +phi_M(M)*T +gamma_M(M)*To"
    " +phi_T(B)*M +gamma_T(B)*Mo +gamma_T(M)*Mo +gamma_T(T)*Mo -gamma_M(T)*To"
    " +sqr(BT)*T +sqr(BM)*M",
    M="+M.lin +B.str(M) +T.str(M) +phi_B(B)*T +gamma_B(B)*To +phi_B(M)*T +gamma_B(M)*To"
    " -gamma_T(B)*Bo -gamma_T(M)*Bo -gamma_T(T)*Bo -gamma_B(T)*To +sqr(MT)*T",
    T="+T.lin +B.str(T) +M.str(T) -phi_B(B)*M -gamma_B(B)*Mo -gamma_M(B)*Bo -gamma_M(M)*Bo"
    " +gamma_M(T)*Bo -gamma_B(M)*Mo +gamma_B(T)*Mo",
)
_EQ_3_15 = dict(
    B="+B.lin +M.str(B) +T.str(B) +phi_M(B)*T +gamma_M(B)*To +phi_M(M)*T +gamma_M(M)*To"
    " +phi_T(B)*M +gamma_T(B)*Mo +gamma_T(M)*Mo +gamma_T(T)*Mo +gamma_M(T)*To"
    " +sqr(BT)*T +sqr(BM)*M",
    M="+M.lin +B.str(M) +T.str(M) +phi_B(B)*T +gamma_B(B)*To +phi_B(M)*T +gamma_B(M)*To"
    " +gamma_B(T)*To -gamma_T(M)*Bo -gamma_T(T)*Bo +sqr(MT)*T",
    T="+T.lin +B.str(T) +M.str(T) -phi_B(B)*M -gamma_B(B)*Mo -gamma_B(T)*Mo -gamma_B(M)*Mo"
    " -gamma_M(M)*Bo -gamma_M(T)*Bo",
)
_EQ_3_16 = dict(
    B="+B.lin +M.str(B) +T.str(B) +phi_M(B)*T +gamma_M(B)*To +phi_M(M)*T +gamma_M(M)*To"
    " +gamma_T(M)*Mo +gamma_T(B)*Mo +gamma_T(T)*Mo -gamma_M(T)*To +sqr(BT)*T +sqr(BM)*M",
    M="+M.lin +B.str(M) +T.str(M) +phi_B(B)*T +gamma_B(B)*To +phi_B(M)*T +gamma_B(M)*To"
    " +phi_T(M)*B -gamma_T(M)*Bo -gamma_B(T)*To -gamma_T(B)*Bo -gamma_T(T)*Bo +sqr(MT)*T",
    T="+T.lin +B.str(T) +M.str(T) -phi_M(M)*B +gamma_M(M)*Bo +gamma_B(M)*Mo +gamma_B(B)*Mo"
    " -gamma_B(T)*Mo +gamma_M(B)*Bo -gamma_M(T)*Bo",
)

_TABLES = {
    ("mcp", "wBMTt"): ("eq. 3.1", _EQ_3_1),
    ("mcp", "BwMTt"): ("eq. 3.2", _EQ_3_2),
    ("mcp", "BMwTt"): ("eq. 3.3", _EQ_3_3),
    ("tcp", "wBMTt"): ("eq. 3.10", _EQ_3_10),
    ("tcp", "BwMTt"): ("eq. 3.11", _EQ_3_11),
    ("tcp", "BMwTt"): ("eq. 3.12", _EQ_3_12),
    ("tcp-compensated-mcp", "wBMTt"): ("eq. 3.14", _EQ_3_14),
    ("tcp-compensated-mcp", "BwMTt"): ("eq. 3.15", _EQ_3_15),
    ("tcp-compensated-mcp", "BMwTt"): ("eq. 3.16", _EQ_3_16),
}

#: the evaluation cases of thesis 3.10: (point, compensation) -> (section, family, words)
CASES = {
    ("MCP", "none"): ("3.10.1", "mcp", "at the MCP, machine without compensation"),
    ("MCP", "MCP"): ("3.10.2", "mcp", "at the MCP, machine compensated at the MCP"),
    ("TCP", "none"): ("3.10.3", "tcp", "at the TCP, machine without compensation"),
    ("TCP", "TCP"): ("3.10.4", "tcp", "at the TCP, machine compensated at the TCP"),
    ("TCP", "MCP"): ("3.10.5", "tcp-compensated-mcp", "at the TCP, machine compensated at the MCP"),
    # not one of the five printed cases: a TCP-compensated machine looked at without a
    # tool is the MCP case with residual angles, i.e. 3.10.2 with a zero-length tool
    ("MCP", "TCP"): ("3.10.2", "mcp", "at the MCP, machine compensated at the TCP"),
}


@dataclass(frozen=True)
class EquationSet:
    """The terms of one equation set and where they are printed."""

    source: str
    configuration: str
    family: str
    terms: tuple[Term, ...]


def evaluation_case(point: str, compensation: str) -> tuple[str, str, str]:
    """(section, family, description) of the thesis 3.10 case for a point and compensation."""
    return CASES[(point, compensation)]


def equation_set(configuration: str, point: str, compensation: str) -> EquationSet:
    """The equation set the case of thesis 3.10 selects for a configuration."""
    _, family, _ = evaluation_case(point, compensation)
    source, table = _TABLES[(family, configuration)]
    return EquationSet(source, configuration, family, _set(source, **table))
