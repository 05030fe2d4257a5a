"""Deciding: quantities, intervals, tests, verdicts, claims, tables, rankings and robustness, from run records."""
