"""Reproducible replication of five particle-filter papers on visual tracking."""

__version__ = "0.1.0"
