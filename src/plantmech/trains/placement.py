"""Where every gear of a general planetary train is, sample by sample: its centre and the
orientation of its body frame in the absolute frame, population-first (P, S) for P designs
at S carrier samples. The one placement the drawings read (the app's scene, the report's
animation, the forward plot of the gears at the start; docs/architecture.md "Train model").

A gear's pitch curve r(theta) is tabulated in its body frame (``trains.curves.Curve``); the
train's motion (``trains.model.TrainMotion``) gives each gear's body angle alpha relative
to the carrier line of its arm and the carrier line's absolute angle C. In the absolute
frame (origin O, x right, y up, angles counter-clockwise, mm and rad):

- shaft k sits at ``shafts[k]`` in the carrier frame, so its centre is
  c = shafts[k] e^{i C} (the sun's shaft 0 is O);
- the gear's body frame is turned by phi = C + alpha, so body angle theta of its pitch
  curve lies at c + r(theta) e^{i (theta + phi)}.

Every gear is placed: the sun once (every arm sees the same sun: C_j + alpha_0j is the
same for all arms j), and per arm the followers (idlers and the planet included), the
compound drivers (a second gear on the previous follower's shaft) and the derived
drivers (the mate of a given follower, seed 000's gear 3) on their shafts. Names are
``trains.gearing.gear_names``' (sun, idler<k>, gear<k>, gear<k>b, planet).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from plantmech.trains.curves import Curve
from plantmech.trains.gearing import gear_names


@dataclass
class PlacedGear:
    """One gear of P designs placed at S' carrier samples.

    ``name``: its role (``gear_names``); ``label``: the name with the arm's number when
    the train has several arms (the sun has none: it is one gear); ``arm``: the arm j whose
    carrier it rides (the sun: 0); ``pair`` and ``side``: the pair it was placed for and
    whether it is that pair's "driver" or "follower"; ``ring``: an internal gear (its
    material outside the pitch curve); ``curve``: its pitch curve in its body frame (mm);
    ``centre`` (P, S') complex mm and ``angle`` (P, S') rad: its centre and the absolute
    orientation phi of its body frame at each sample."""

    name: str
    label: str
    arm: int
    pair: int
    side: str
    ring: bool
    curve: Curve = field(repr=False)
    centre: np.ndarray = field(repr=False)
    angle: np.ndarray = field(repr=False)

    def outline(self, theta: np.ndarray | None = None) -> np.ndarray:
        """The pitch curve placed, (P, S', n) complex mm: c + r(theta) e^{i (theta + phi)}
        at body angles ``theta`` (n,) rad (None: the curve's own grid, its tabulated
        radii)."""
        if theta is None:
            theta, r = self.curve.theta, self.curve.r
        else:
            theta = np.asarray(theta, dtype=float)
            r = self.curve(theta[None, :])[0]
        body = r * _cis(theta)[None, :]  # (P|1, n) in the body frame
        return self.centre[:, :, None] + body[:, None, :] * _cis(self.angle)[:, :, None]


def _cis(angle) -> np.ndarray:
    """e^(i angle) for real angles (rad), as cos + i sin (the app's scene rounds these to
    the micrometre: the same arithmetic as its own)."""
    angle = np.asarray(angle, dtype=float)
    out = np.empty(angle.shape, dtype=complex)
    np.cos(angle, out=out.real)
    np.sin(angle, out=out.imag)
    return out


def place_gears(motion, samples: np.ndarray | None = None) -> list[PlacedGear]:
    """Every gear of the trains of ``motion`` (``trains.model.TrainMotion``: P designs, J
    arms) at the carrier samples ``samples`` (indices into ``motion.carrier_angle``; None:
    all): the sun first, then per arm and pair, the pair's driver where it is a gear of
    its own (the sun, a compound or a derived driver; an idler's pair is driven by the
    follower placed before) and its follower. Each with centre and body-frame angle
    (P, S') in the absolute frame (mm, rad)."""
    built = motion.built
    pairs = built.train.pairs
    names = gear_names(built)
    k = np.arange(motion.carrier.shape[-1]) if samples is None else np.asarray(samples)
    J = motion.carrier.shape[1]
    followers = built.followers
    out: list[PlacedGear] = []
    for j in range(J):
        carrier = motion.carrier[:, j][:, k]  # (P, S') absolute carrier-line angle C
        turn = _cis(carrier)
        for i, spec in enumerate(pairs):
            own_driver = i == 0 or spec.driver is not None or spec.follower is not None
            sides = []
            if own_driver and not (i == 0 and j > 0):  # the sun once
                sides.append(("driver", names[i][0], built.drivers[i], i,
                              motion.driver_angles[i], spec.kind == "internal"))
            sides.append(("follower", names[i][1], followers[i], i + 1,
                          motion.gear_angles[i + 1], spec.kind == "internal_ring_follower"))
            for side, name, curve, shaft, alpha, ring in sides:
                label = name if name == "sun" or J == 1 else f"{name} {j + 1}"
                centre = built.shafts[:, shaft, None] * turn
                angle = carrier + alpha[:, j][:, k]
                out.append(PlacedGear(name, label, j, i, side, ring, curve, centre, angle))
    return out


__all__ = ["PlacedGear", "place_gears"]
