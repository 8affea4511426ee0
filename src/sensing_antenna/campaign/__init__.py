"""Experiment campaigns: declarative specs, parallel runs, tables and reports (Section 5)."""
