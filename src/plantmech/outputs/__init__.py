"""Outputs: reports (JSON, CSV) and plots. Units on every column and axis."""
