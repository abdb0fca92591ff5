"""Cast shadows for the ray caster (``shadows=True``): a shadow map along the light.

The scene light is directional (:class:`~homing_gym.render.panorama.Lighting`: ``direction``
towards the light). Every triangle is projected onto the plane perpendicular to it and
rasterised into a grid (:data:`MAX_CELLS` cells a side at most, cells no finer than
:data:`FINEST` metres) that keeps, per cell, the greatest height towards the light of
anything there: the first surface the light meets. A shaded point lies in shadow when
something in its cell stands higher towards the light than the point itself by more than
:data:`BIAS_CELLS` cells plus the depth its own surface gains across a cell (its slope
to the light); it then gets the ambient light alone (no diffuse
term), as a face turned from the light does. This is one shadow "ray" per pixel, looked up
instead of cast, so its cost is the map (once per world and light direction) and a
lookup per ray. The robot's own body is not in the world mesh and casts no shadow.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

#: The map's largest side (cells) and its finest cell (metres).
MAX_CELLS, FINEST = 1024, 0.01
#: Depth tolerance, in cells, against a surface shadowing itself.
BIAS_CELLS = 2.0


@dataclass(frozen=True)
class ShadowMap:
    """``depth[i, j]``: greatest height towards the light at map point ``origin + (i, j) *
    cell`` in the basis ``axes = (u, v, l)`` (rows of a 3 x 3 matrix; ``l`` towards the
    light); ``-inf`` where nothing is."""

    depth: np.ndarray
    axes: np.ndarray
    origin: np.ndarray
    cell: float


def light_axes(direction) -> np.ndarray:
    """An orthonormal basis ``(u, v, l)`` with ``l`` towards the light."""
    l = np.asarray(direction, np.float64)
    l = l / np.linalg.norm(l)
    helper = np.array([0.0, 0.0, 1.0]) if abs(l[2]) < 0.9 else np.array([1.0, 0.0, 0.0])
    u = np.cross(helper, l)
    u /= np.linalg.norm(u)
    return np.stack([u, np.cross(l, u), l])


@njit(cache=True, error_model="numpy", nogil=True)
def _rasterise(projected: np.ndarray, origin: np.ndarray, cell: float,
               depth: np.ndarray) -> None:
    """Keep per cell the greatest depth of the triangles ``projected (N, 3, 3)`` (map
    coordinates u, v and depth) covering its centre."""
    nu, nv = depth.shape
    for t in range(projected.shape[0]):
        p = projected[t]
        u0, v0 = (p[0, 0] - origin[0]) / cell, (p[0, 1] - origin[1]) / cell
        u1, v1 = (p[1, 0] - origin[0]) / cell, (p[1, 1] - origin[1]) / cell
        u2, v2 = (p[2, 0] - origin[0]) / cell, (p[2, 1] - origin[1]) / cell
        area = (u1 - u0) * (v2 - v0) - (u2 - u0) * (v1 - v0)
        if area == 0.0:
            continue                       # seen edge-on by the light: casts no shadow
        i0 = max(int(math.floor(min(u0, u1, u2))), 0)
        i1 = min(int(math.ceil(max(u0, u1, u2))), nu - 1)
        j0 = max(int(math.floor(min(v0, v1, v2))), 0)
        j1 = min(int(math.ceil(max(v0, v1, v2))), nv - 1)
        for i in range(i0, i1 + 1):
            for j in range(j0, j1 + 1):
                a = ((u1 - i) * (v2 - j) - (u2 - i) * (v1 - j)) / area
                b = ((u2 - i) * (v0 - j) - (u0 - i) * (v2 - j)) / area
                c = 1.0 - a - b
                if a < 0.0 or b < 0.0 or c < 0.0:
                    continue
                d = a * p[0, 2] + b * p[1, 2] + c * p[2, 2]
                if d > depth[i, j]:
                    depth[i, j] = d


def shadow_map(triangles: np.ndarray, direction) -> ShadowMap:
    """The shadow map of ``triangles (N, 3, 3)`` (metres) for light from ``direction``."""
    axes = light_axes(direction)
    projected = np.ascontiguousarray(triangles.astype(np.float64) @ axes.T)
    low, high = projected[..., :2].reshape(-1, 2).min(0), projected[..., :2].reshape(-1, 2).max(0)
    cell = max(FINEST, float(np.max(high - low)) / (MAX_CELLS - 1))
    shape = tuple(int(v) for v in np.ceil((high - low) / cell).astype(int) + 1)
    depth = np.full(shape, -np.inf)
    _rasterise(projected, low, cell, depth)
    return ShadowMap(depth, axes, low, cell)


@njit(cache=True, error_model="numpy", nogil=True)
def in_shadow(depth: np.ndarray, axes: np.ndarray, origin: np.ndarray, cell: float,
              x: float, y: float, z: float, facing: float) -> bool:
    """Whether the point ``(x, y, z)`` lies in the shadow of the map (see the module);
    ``facing``: the cosine between its surface's normal and the light, which widens the
    tolerance on slanted surfaces (their depth changes across a cell)."""
    u = axes[0, 0] * x + axes[0, 1] * y + axes[0, 2] * z
    v = axes[1, 0] * x + axes[1, 1] * y + axes[1, 2] * z
    d = axes[2, 0] * x + axes[2, 1] * y + axes[2, 2] * z
    i = int(round((u - origin[0]) / cell))
    j = int(round((v - origin[1]) / cell))
    if i < 0 or j < 0 or i >= depth.shape[0] or j >= depth.shape[1]:
        return False
    c = max(abs(facing), 0.1)
    return depth[i, j] > d + (BIAS_CELLS + math.sqrt(1.0 - c * c) / c) * cell
