"""plantmech: design of planting mechanisms driven by non-circular planetary gear trains.

Layers (data flows downwards only):
geometry -> gears -> mechanisms -> objectives -> outputs -> interfaces.
Internal units: mm and radians. Degrees and m/s appear only at the boundaries
(design files, reports, plots).
"""

__version__ = "0.1.0"
