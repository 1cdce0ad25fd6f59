"""An angular error from two linear positioning measurements at a known displacement
(``esp angular``; Longstaff 2002, 3.08.1): its text and its report. The computation is
:mod:`esp.core.angular`, which the machine configuration also uses for ``from_linear``
sources."""
