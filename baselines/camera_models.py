"""Where an image pixel looks: bearing and elevation of pixel coordinates, for the two
cameras of homing-gym (the robot's panorama and an ordinary perspective view).

Coordinates are *pixel-index* coordinates: ``x = 3.0`` is the value stored in column 3,
``x = 3.5`` halfway to column 4. Bearings are radians counter-clockwise from the robot's
heading; elevations radians up from the horizontal. Both models give the horizontal
distance (metres) of an upright object of known height from the rows of its top and
bottom edges (:meth:`distance`), the "distance from apparent size" of Briggs et al. 2000
§4.1.
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from dataclasses import dataclass

import numpy as np

from homing_gym.render.panorama import column_bearing, row_elevation


class CameraModel(ABC):
    """What both models share; subclasses give ``bearing(x)`` and ``tan_elevation(x, y)``
    and say whether columns wrap around (``wraps``)."""

    wraps: bool = False

    @abstractmethod
    def bearing(self, x):
        """Bearing (radians, CCW from the heading) of column coordinate ``x``."""

    @abstractmethod
    def tan_elevation(self, x, y):
        """Tangent of the elevation of the ray through pixel coordinate ``(x, y)``."""

    def distance(self, x: float, y_top: float, y_bottom: float, height: float) -> float:
        """Horizontal distance (m) of an upright object ``height`` metres tall whose top
        and bottom edges are at rows ``y_top`` < ``y_bottom`` in column ``x``."""
        span = float(self.tan_elevation(x, y_top) - self.tan_elevation(x, y_bottom))
        return height / span if span > 0 else math.inf


@dataclass(frozen=True)
class PanoramaModel(CameraModel):
    """The env's cylindrical panorama (``homing_gym.render.panorama``): ``width`` x ``height``
    pixels, vertical field of view ``vfov`` (radians). Pixel index ``j`` is the centre
    ``j + 0.5`` of the continuous coordinate, so bearing ``pi - 2 pi (x + 0.5) / W``."""

    width: int
    height: int
    vfov: float = math.radians(60)
    wraps: bool = True

    def bearing(self, x):
        return column_bearing(np.asarray(x, dtype=np.float64) + 0.5, self.width)

    def tan_elevation(self, x, y):
        return np.tan(row_elevation(np.asarray(y, dtype=np.float64) + 0.5, self.height,
                                    self.vfov))


@dataclass(frozen=True)
class PerspectiveModel(CameraModel):
    """A pinhole view (``homing_gym.render.perspective``): ``width`` x ``height`` pixels, focal
    length ``focal`` pixels, zero pitch and roll; pixel index ``i`` is the ray through
    image coordinate ``i + pixel_centre`` (0 for TinyRenderer, 0.5 for OpenGL)."""

    width: int
    height: int
    focal: float
    pixel_centre: float = 0.0
    wraps: bool = False

    @classmethod
    def from_fov(cls, width: int, height: int, hfov: float,
                 pixel_centre: float = 0.0) -> "PerspectiveModel":
        """The model of a ``width`` x ``height`` view with horizontal field of view
        ``hfov`` radians."""
        return cls(width, height, width / (2 * math.tan(hfov / 2)), pixel_centre)

    def _offsets(self, x, y):
        u = self.width / 2 - np.asarray(x, dtype=np.float64) - self.pixel_centre
        v = self.height / 2 - np.asarray(y, dtype=np.float64) - self.pixel_centre
        return u, v

    def bearing(self, x):
        u, _ = self._offsets(x, 0.0)
        return np.arctan2(u, self.focal)

    def tan_elevation(self, x, y):
        u, v = self._offsets(x, y)
        return v / np.hypot(self.focal, u)
