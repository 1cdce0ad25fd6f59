"""ISO 230-2 positioning tests and VDI 3441 (``esp iso230-2``)."""
