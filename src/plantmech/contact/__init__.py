"""Tooth-contact verification of written gear files (issue 15)."""
