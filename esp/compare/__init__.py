"""Two analyses of one machine compared (``esp compare``)."""
