"""Parts the open-country families (``grassland``, ``desert``) build from: the ground disc
of :mod:`~homing_gym.scenes.random_nature` tinted per world, a band of skyline at a
distance, closed rods between two points (cactus stems, dead twigs), and :class:`Spots`,
which places obstacles so that the robot's way between them stays open. Units: metres,
z up, the floor at z = 0; colours RGB in [0, 1].
"""

from __future__ import annotations

import math

import numpy as np

from homing_gym.scenes.mesh_part import MeshPart
from homing_gym.scenes.random_nature import GAP, _ground, _unit_trunk

Mesh = tuple[np.ndarray, np.ndarray]


def tinted_ground(rng: np.random.Generator, tint: np.ndarray) -> MeshPart:
    """random_nature's ground disc (28 m radius, faces of varied shade) drawn from ``rng``,
    its faces' mean colour moved to ``tint`` (RGB) and their variation about it halved."""
    disc = _ground(rng)
    colors = (1 + (disc.face_colors / disc.face_colors.mean(axis=0) - 1) / 2) * np.asarray(tint)
    return MeshPart(disc.vertices, disc.faces, np.clip(colors, 0, 1), collision=False,
                    name="ground", solid_faces=())           # an open surface


def skyline_band(distance: np.ndarray, heights: np.ndarray, colors: np.ndarray, name: str,
                 lean: float = 0.02) -> MeshPart:
    """A closed ring of upright quads facing the origin (TinyRenderer culls back faces):
    ``len(heights)`` feet evenly spaced in azimuth from +x, counter-clockwise, each
    ``distance`` metres out (one value or one per foot) and its top edge ``heights``
    metres up, leaning outwards by the fraction ``lean`` of the distance; ``colors``: one
    RGB per quad (the band from foot k to foot k + 1)."""
    n = len(heights)
    a = np.linspace(0, 2 * math.pi, n, endpoint=False)
    distance = np.broadcast_to(np.asarray(distance, np.float64), (n,))
    foot = np.stack([distance * np.cos(a), distance * np.sin(a), np.zeros(n)], axis=1)
    top = foot * (1 + lean) + np.stack([np.zeros(n), np.zeros(n), heights], axis=1)
    k = np.arange(n)
    k1 = (k + 1) % n
    faces = np.stack([np.stack([k, n + k1, k1], 1), np.stack([k, n + k, n + k1], 1)],
                     1).reshape(-1, 3)
    return MeshPart(np.concatenate([foot, top]), faces,
                    np.clip(np.repeat(np.asarray(colors), 2, axis=0), 0, 1),
                    collision=False, name=name, solid_faces=())        # an open band


def rod(start, end, radius: float) -> Mesh:
    """A closed 10-sided cylinder ``(vertices, faces)`` of ``radius`` metres from point
    ``start`` to point ``end`` (its end caps' centres), wound outwards."""
    start, end = np.asarray(start, np.float64), np.asarray(end, np.float64)
    axis = end - start
    length = float(np.linalg.norm(axis))
    unit, faces = _unit_trunk()
    local = unit * [radius, radius, length] + [0.0, 0.0, length / 2]
    w = axis / length
    helper = np.array([1.0, 0.0, 0.0]) if abs(w[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    u = np.cross(helper, w)
    u /= np.linalg.norm(u)
    v = np.cross(w, u)                                 # (u, v, w) right-handed: a rotation
    return local @ np.stack([u, v, w]) + start, faces


class Spots:
    """Floor points for obstacles in a world whose free floor is ``|x| <= hx``,
    ``|y| <= hy``: each obstacle's footprint circle keeps :data:`GAP` (the robot's
    width and more) from every other's and from the free floor's edges, so the free floor
    stays one open region."""

    def __init__(self, rng: np.random.Generator, hx: float, hy: float):
        self.rng, self.hx, self.hy = rng, hx, hy
        self.placed: list[tuple[float, float, float]] = []      # x, y, footprint radius

    def _take(self, xy: np.ndarray, reach: float) -> tuple[float, float] | None:
        if all(math.dist(xy, p[:2]) >= reach + p[2] + GAP for p in self.placed):
            self.placed.append((float(xy[0]), float(xy[1]), reach))
            return float(xy[0]), float(xy[1])
        return None

    def inside(self, reach: float) -> tuple[float, float] | None:
        """A spot for a footprint of radius ``reach`` (metres) inside the free floor,
        :data:`GAP` from its edges too, or ``None`` after 50 tries."""
        edge = reach + GAP
        for _ in range(50):
            xy = self.rng.uniform([-self.hx + edge, -self.hy + edge],
                                  [self.hx - edge, self.hy - edge])
            if (spot := self._take(xy, reach)) is not None:
                return spot
        return None

    def beyond(self, reach: float, far: float) -> tuple[float, float] | None:
        """A spot for a footprint of radius ``reach`` outside the free floor, at least
        0.5 m beyond its edge and at most ``far`` metres from its middle, or ``None``
        after 50 tries."""
        near = min(self.hx, self.hy) + 0.5
        for _ in range(50):
            r, a = self.rng.uniform(near, far), self.rng.uniform(0, 2 * math.pi)
            xy = np.array([r * math.cos(a), r * math.sin(a)])
            if max(abs(xy[0]) - self.hx, abs(xy[1]) - self.hy) >= 0.5 + reach:
                if (spot := self._take(xy, reach)) is not None:
                    return spot
        return None
