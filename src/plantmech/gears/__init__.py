"""Gear pairs: ratio laws, pitch curves, closure, toothless sectors."""
