"""ISO 230-6 body diagonals predicted from the machine's errors (``esp diagonals``)."""
