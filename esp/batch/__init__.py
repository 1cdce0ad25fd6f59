"""Many machines analysed and summarised (``esp batch``)."""
