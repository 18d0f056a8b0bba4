"""Curves: closed trajectories and periodic radius functions."""
