"""Automatic optimization of both mechanisms (problem definitions on the batch APIs,
pymoo algorithms, run records)."""
