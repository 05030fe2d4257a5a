"""Experiment runner: config -> runs -> parallel execution -> result store."""
