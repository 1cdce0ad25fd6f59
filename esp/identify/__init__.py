"""Errors identified from indirect measurements (``esp identify``): ball plates,
ballbars, machine checking gauges and tracking interferometers (Longstaff 2002, chapters 8-10).
"""
