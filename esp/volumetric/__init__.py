"""The volumetric analysis (``esp analyse``): its text, JSON, CSV tables and figures."""
