"""Reading and writing measurement data and configuration."""
