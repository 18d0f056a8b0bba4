"""Mechanisms: one module per train type, inverse and forward kinematics."""
