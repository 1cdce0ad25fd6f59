"""Rendering of results: text, JSON, tables and plots. Nothing in the numeric core imports
this package."""
