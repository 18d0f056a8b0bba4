"""The general non-circular planetary train (issue 16; docs/architecture.md, "Train model").

``curves``: pitch-curve families tabulated for P designs; ``pairs``: one pair's rolling law,
closure and mate; ``model``: a chain of pairs on a carrier and its forward kinematics,
population-first; ``spec``: a ``mechanism = "planetary"`` design file as a ``Train``.

>>> from plantmech.trains.curves import ellipse
>>> from plantmech.trains.model import PairSpec, Train, forward
>>> sun = ellipse(25.0, 0.18, 2048)  # A = 25 mm about a focus
>>> m = forward(Train([PairSpec("external", sun), PairSpec("external")], arms=2), 360)
>>> m.tip.shape, round(float(m.built.centre_distances[0, 0]), 9)
((1, 2, 360), 50.0)
"""
