"""Aggregation, tables, figures and HTML pages; reads only the result store."""
