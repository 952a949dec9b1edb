"""The layout of a street, drawn first: every other outdoor element is placed relative to it. Units: metres.

World frame: y up, the road on y = 0, x across the street (its centre line at x = 0), z along it (the camera at
z = 0 looking towards +z). Traffic keeps right: the camera's lanes are at x > 0.
"""
from __future__ import annotations

import dataclasses

STYLES = ("urban", "residential", "open")


@dataclasses.dataclass(frozen=True)
class Street:
    """One street: its style, lanes per direction, lane width, parking lane width (0 = none), sidewalk width
    (0 = none), curb height and length (metres)."""

    style: str
    lanes: int
    lane_width: float
    parking: float
    sidewalk: float
    curb: float
    length: float

    @property
    def half_width(self) -> float:
        """From the centre line to the curb: the lanes of one direction and the parking lane."""
        return self.lanes * self.lane_width + self.parking

    @property
    def edge(self) -> float:
        """From the centre line to the far edge of the sidewalk: where the terrain (and the properties) begin."""
        return self.half_width + self.sidewalk


@dataclasses.dataclass(frozen=True)
class StreetRanges:
    """What a street's layout is drawn from: the weights of STYLES, lanes per direction ([low, high), one on
    residential streets), and (metres) the lane width, a parking lane's width (on non-open streets, with probability
    `parking_p`), the sidewalk width (none on open roads), the curb height and the street's length."""

    style_weights: tuple[float, float, float] = (0.4, 0.4, 0.2)
    lanes: tuple[int, int] = (1, 3)
    lane_width_m: tuple[float, float] = (2.9, 3.7)
    parking_p: float = 0.75
    parking_m: tuple[float, float] = (2.0, 2.5)
    sidewalk_m: tuple[float, float] = (1.5, 4.0)
    curb_m: tuple[float, float] = (0.08, 0.18)
    length_m: tuple[float, float] = (70.0, 250.0)


STREET = StreetRanges()


def street_layout(rng, r: StreetRanges = STREET) -> Street:
    """A street drawn from `rng`."""
    style = STYLES[int(rng.choice(3, p=list(r.style_weights)))]
    lanes = int(rng.integers(*r.lanes)) if style != "residential" else 1
    lane_width = rng.uniform(*r.lane_width_m)
    parking = rng.uniform(*r.parking_m) if (style != "open" and rng.random() < r.parking_p) else 0.0
    sidewalk = rng.uniform(*r.sidewalk_m) if style != "open" else 0.0
    curb = rng.uniform(*r.curb_m)
    length = rng.uniform(*r.length_m)
    return Street(style, lanes, lane_width, parking, sidewalk, curb, length)
