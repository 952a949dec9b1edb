"""Daylight over a street: the sun (sometimes behind an overcast sky), a sky with clouds and a sun glow, and the
ambient light they give. Directions are world unit vectors (y up); colours linear RGB (3, 1)."""
from __future__ import annotations

import dataclasses
import math
from typing import Callable

import numpy as np

from lipjax.data.synthetic.colour import _c_grey, _hsv, _mix
from lipjax.data.synthetic.noise import _fbm
from lipjax.data.synthetic.scene import Light


@dataclasses.dataclass(frozen=True)
class DaylightRanges:
    """The probability of an overcast sky; the sun's elevation and azimuth (radians) and intensity (clear /
    overcast); the sky's brightness gain; the ambient intensity (clear / overcast); the cloud cover in [0, 1]
    (clear / overcast)."""

    overcast_p: float = 0.3
    sun_elevation: tuple[float, float] = (0.3, 1.15)
    sun_azimuth: tuple[float, float] = (-math.pi, math.pi)
    sun_clear: tuple[float, float] = (2.5, 4.0)
    sun_overcast: tuple[float, float] = (0.4, 1.0)
    ambient_clear: tuple[float, float] = (0.5, 0.9)
    ambient_overcast: tuple[float, float] = (0.9, 1.5)
    clouds_clear: tuple[float, float] = (0.0, 1.0)
    clouds_overcast: tuple[float, float] = (0.6, 1.0)
    sky_gain: tuple[float, float] = (1.3, 2.2)


@dataclasses.dataclass(frozen=True)
class Daylight:
    """The sun, the ambient colour, the sky's radiance ((dx, dy, dz) unit world directions -> (3, n)) and the
    horizon's colour (for distance haze)."""

    sun: Light
    ambient: np.ndarray
    sky: Callable
    haze_color: np.ndarray


DAYLIGHT = DaylightRanges()


def daylight(rng, r: DaylightRanges = DAYLIGHT) -> Daylight:
    """Sun, sky and ambient light drawn from `rng`."""
    overcast = rng.random() < r.overcast_p
    el, az = rng.uniform(*r.sun_elevation), rng.uniform(*r.sun_azimuth)
    sun_dir = (math.cos(el) * math.sin(az), math.sin(el), math.cos(el) * math.cos(az))
    sun_c = _hsv(rng.uniform(0.08, 0.13), rng.uniform(0.05, 0.25), 1.0) * (rng.uniform(*r.sun_overcast) if overcast
                                                                             else rng.uniform(*r.sun_clear))
    sky_top = _hsv(rng.uniform(0.55, 0.63), rng.uniform(0.0, 0.15) if overcast else rng.uniform(0.3, 0.7),
                   rng.uniform(0.6, 0.95))
    sky_hor = _hsv(rng.uniform(0.55, 0.63), rng.uniform(0.0, 0.2), rng.uniform(0.8, 1.0))
    ambient = (sky_top * 0.5 + sky_hor * 0.5) * (rng.uniform(*r.ambient_overcast) if overcast
                                                 else rng.uniform(*r.ambient_clear))
    clouds = rng.uniform(*r.clouds_clear) if not overcast else rng.uniform(*r.clouds_overcast)
    cloud_c = _c_grey(rng, 0.75, 1.0)
    sky_gain = rng.uniform(*r.sky_gain)
    cx0, cz0 = rng.uniform(0, 256, 2)

    def sky(dx, dy, dz):
        e = np.clip(dy, 0.0, 1.0)
        col = _mix(sky_hor, sky_top, np.sqrt(e))
        inv = 1.0 / np.maximum(dy, 0.03)
        n = _fbm(dx * inv * 0.7 + cx0, dz * inv * 0.7 + cz0, 4)
        cov = np.clip((n - (1.0 - clouds) * 0.7 - 0.2) * 3.0, 0.0, 1.0) * np.clip(e * 8.0, 0.0, 1.0)
        col = col + (cloud_c * (0.75 + 0.5 * n) - col) * cov
        sd = dx * sun_dir[0] + dy * sun_dir[1] + dz * sun_dir[2]
        glow = np.maximum(sd, 0.0)
        for _ in range(5):  # ** 32
            glow = glow * glow
        glow *= 0.0 if overcast else 2.0
        return col * sky_gain + glow

    sun = Light(sun_c, direction=sun_dir, shadow_blur=1 if not overcast else 4)
    return Daylight(sun, ambient, sky, sky_hor * sky_gain * 0.8)
