"""Where mesh parts block the robot: their cut through the height band, rasterised.

The robot drives on the plane z = 0. A mesh part's triangles block it where they pass
through the scene's ``height_band`` = (low, high) metres above the floor (default
0.02-0.35 m: above floor-level detail such as rugs or the mesh's own ground, up to just
over the camera): a table's legs block, its top does not. The triangles are clipped to the
band with ``trimesh.intersections.slice_faces_plane``; the clipped polygons, seen from
above, are filled into an occupancy grid (OpenCV, sub-pixel precision; a vertical wall
fills the cells its trace crosses) and ``scipy.ndimage.distance_transform_edt`` gives each
cell's distance to the nearest blocked cell. A :class:`ClearanceField` reads that field with
bilinear interpolation, less one cell size, so it never claims more room than there is
(it may claim up to about one cell less). The inside of a closed solid (a watertight
component wound outwards: a pillar, a rock) is blocked too: the floor outline of its
triangles in the band is filled (``scipy.ndimage.binary_fill_holes``; a solid with a hole
through it, a ring, is filled whole); an inward-wound shell (a room modelled as one box
seen from inside) and open surfaces are not filled. The floor under the ground is
blocked as well (:func:`underground`): where the first surface above the band
over a grid point, the lowest triangle there higher than the band's top, faces up (the
robot would see its back), as under a terrain's hill that rises above the band. A
ceiling, a table top or a roof seen from inside faces down and leaves the floor free;
nearly vertical triangles (``|normal z| <`` :data:`STEEP`) hide what lies above them but
face neither way. A z-buffer over the grid points (numba) finds that surface. Only
colliding parts count, for this as for the rest. The same triangles (those reaching into
the band) become the PyBullet collision body (:mod:`homing_gym.sim.simulator`), so what the
planner avoids is what the robot bumps into.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import cv2
import numpy as np
from numba import njit
from scipy import ndimage

from homing_gym.scenes.mesh_part import MeshPart

#: Finest grid cell (metres) and the most cells a field may have (coarser for big worlds).
RESOLUTION, MAX_CELLS = 0.02, 4_000_000
#: Cells of grid beyond the scene bounds (obstacles just outside still narrow the room).
MARGIN = 0.5
_SHIFT = 8          # OpenCV sub-pixel bits
#: Triangles whose unit normal has ``|z|`` below this (within about 6 degrees of vertical)
#: face neither up nor down: in :func:`underground` they block nothing.
STEEP = 0.1


def band_faces(part: MeshPart, band: tuple[float, float]) -> np.ndarray:
    """Indices of the faces of ``part`` whose height range meets ``band`` (metres)."""
    z = part.triangles[:, :, 2]
    return np.flatnonzero((z.max(axis=1) >= band[0]) & (z.min(axis=1) <= band[1]))


def band_triangles(part: MeshPart, band: tuple[float, float]) -> np.ndarray:
    """Corners ``(M, 3, 3)`` of the triangles of ``part`` clipped to ``low <= z <= high``."""
    return clipped(part.vertices, part.faces[band_faces(part, band)], band)


def clipped(vertices: np.ndarray, faces: np.ndarray, band: tuple[float, float]) -> np.ndarray:
    """Corners ``(M, 3, 3)`` of the triangles ``faces`` clipped to ``low <= z <= high``
    (``trimesh.intersections.slice_faces_plane`` at both planes)."""
    from trimesh.intersections import slice_faces_plane   # only mesh worlds need trimesh

    if len(faces) == 0:
        return np.zeros((0, 3, 3))
    for normal, origin in (((0, 0, 1), (0, 0, band[0])), ((0, 0, -1), (0, 0, band[1]))):
        vertices, faces = slice_faces_plane(vertices, faces, np.array(normal, float),
                                            np.array(origin, float))[:2]
        if len(faces) == 0:
            return np.zeros((0, 3, 3))
    return np.asarray(vertices)[np.asarray(faces)]


@dataclass(frozen=True)
class ClearanceField:
    """Distance (metres) from each grid point to the nearest blocked cell, less one cell;
    ``field[i, j]`` at floor point ``origin + (i, j) * resolution``."""

    field: np.ndarray
    origin: tuple[float, float]
    resolution: float

    def __call__(self, points: np.ndarray) -> np.ndarray:
        """Clearance at floor points ``(N, 2)``; 0 outside the grid."""
        idx = (np.asarray(points, np.float64) - self.origin) / self.resolution
        return ndimage.map_coordinates(self.field, idx.T, order=1, mode="constant", cval=0.0)


def rasterise(triangles: np.ndarray, origin, resolution: float,
              shape: tuple[int, int]) -> np.ndarray:
    """Boolean grid ``shape = (nx, ny)``, True in every cell a triangle ``(M, 3, 2)``
    (floor points, metres) covers or whose outline crosses."""
    grid = np.zeros((shape[1], shape[0]), np.uint8)          # OpenCV: rows are y
    if len(triangles):
        scale = 2 ** _SHIFT / resolution
        pts = list(np.round((np.asarray(triangles) - origin) * scale).astype(np.int32))
        cv2.fillPoly(grid, pts, 1, cv2.LINE_8, _SHIFT)
        cv2.polylines(grid, pts, True, 1, 1, cv2.LINE_8, _SHIFT)
    return grid.T.astype(bool)


def solids(part: MeshPart, band: tuple[float, float]) -> list[np.ndarray]:
    """The closed solids of ``part`` (:attr:`MeshPart.solids`) that reach into ``band``,
    each as its triangles clipped to the band (:func:`clipped`)."""
    if len(band_faces(part, band)) == 0:
        return []
    found = []
    for faces in part.solids:
        tris = clipped(part.vertices, part.faces[faces], band)
        if len(tris):
            found.append(tris)
    return found


def _fill_solid(blocked: np.ndarray, tris: np.ndarray, origin, resolution: float) -> None:
    """Mark in ``blocked`` the cells of one solid's floor outline and everything it
    encloses (``scipy.ndimage.binary_fill_holes`` in a window around the whole solid,
    then the part of the window on the grid)."""
    xy = tris[..., :2].reshape(-1, 2)
    low = np.floor((xy.min(axis=0) - origin) / resolution).astype(int) - 1
    high = np.ceil((xy.max(axis=0) - origin) / resolution).astype(int) + 2
    a, b = np.maximum(low, 0), np.minimum(high, blocked.shape)
    if np.any(b <= a):
        return                                  # wholly off the grid
    window = ndimage.binary_fill_holes(rasterise(tris[..., :2], origin + low * resolution,
                                                 resolution, tuple(high - low)))
    blocked[a[0]:b[0], a[1]:b[1]] |= window[a[0] - low[0]:b[0] - low[0],
                                            a[1] - low[1]:b[1] - low[1]]


@njit(cache=True, error_model="numpy")
def _lowest_facing(tri, up, origin, resolution, shape, floor):  # pragma: no cover (numba)
    """z-buffer of the triangles ``tri`` ``(M, 3, 3)`` sampled at the grid points: per
    point the height of the lowest triangle over it above ``floor`` (``inf``: none) and
    whether that triangle faces up (``up[m]``)."""
    height = np.full(shape, np.inf)
    facing = np.zeros(shape, np.bool_)
    for m in range(tri.shape[0]):
        x0, y0, z0 = tri[m, 0, 0], tri[m, 0, 1], tri[m, 0, 2]
        x1, y1, z1 = tri[m, 1, 0], tri[m, 1, 1], tri[m, 1, 2]
        x2, y2, z2 = tri[m, 2, 0], tri[m, 2, 1], tri[m, 2, 2]
        det = (x1 - x0) * (y2 - y0) - (x2 - x0) * (y1 - y0)
        if det == 0.0:
            continue
        i0 = max(int(np.ceil((min(x0, x1, x2) - origin[0]) / resolution)), 0)
        i1 = min(int(np.floor((max(x0, x1, x2) - origin[0]) / resolution)), shape[0] - 1)
        j0 = max(int(np.ceil((min(y0, y1, y2) - origin[1]) / resolution)), 0)
        j1 = min(int(np.floor((max(y0, y1, y2) - origin[1]) / resolution)), shape[1] - 1)
        for i in range(i0, i1 + 1):
            px = origin[0] + i * resolution
            for j in range(j0, j1 + 1):
                py = origin[1] + j * resolution
                a = ((x1 - px) * (y2 - py) - (x2 - px) * (y1 - py)) / det
                b = ((x2 - px) * (y0 - py) - (x0 - px) * (y2 - py)) / det
                c = 1.0 - a - b
                if a < -1e-9 or b < -1e-9 or c < -1e-9:     # on an edge: both sides
                    continue
                z = a * z0 + b * z1 + c * z2
                if floor < z < height[i, j]:
                    height[i, j] = z
                    facing[i, j] = up[m]
    return height, facing


def underground(parts: tuple[MeshPart, ...], band, origin, resolution: float,
                shape: tuple[int, int]) -> np.ndarray:
    """Boolean grid ``shape`` (point ``(i, j)`` at ``origin + (i, j) * resolution``), True
    where the first surface above the band, the lowest triangle of the colliding ``parts``
    higher than ``band[1]`` at that point, faces up (normal z > :data:`STEEP` of its
    length): the robot would see it from behind, from under the ground or inside a solid.
    A ceiling or a table top, seen from below, faces down; a nearly vertical triangle
    hides what lies above it but blocks nothing."""
    triangles = [part.triangles[part.triangles[:, :, 2].max(axis=1) > band[1]]
                 for part in parts if part.collision]
    triangles = np.concatenate([np.zeros((0, 3, 3))] + triangles)
    if not len(triangles):
        return np.zeros(shape, bool)
    normal = np.cross(triangles[:, 1] - triangles[:, 0], triangles[:, 2] - triangles[:, 0])
    length = np.linalg.norm(normal, axis=1)
    _, facing = _lowest_facing(np.ascontiguousarray(triangles, np.float64),
                               normal[:, 2] > STEEP * length, np.asarray(origin, np.float64),
                               float(resolution), shape, float(band[1]))
    return facing


def clearance_field(parts: tuple[MeshPart, ...], bounds, band) -> ClearanceField | None:
    """The field of the colliding ``parts`` over ``bounds`` (plus :data:`MARGIN`): their
    triangles in ``band``, the insides of their closed solids and the floor under the
    ground (:func:`underground`); ``None`` when none of them blocks."""
    colliding = [part for part in parts if part.collision]
    triangles = np.concatenate([np.zeros((0, 3, 3))]
                               + [band_triangles(part, band) for part in colliding])[..., :2]
    if not len(triangles) and not any(part.vertices[:, 2].max() > band[1]
                                      for part in colliding):
        return None
    (xmin, ymin), (xmax, ymax) = bounds
    width, depth = xmax - xmin + 2 * MARGIN, ymax - ymin + 2 * MARGIN
    resolution = max(RESOLUTION, math.sqrt(width * depth / MAX_CELLS))
    shape = (int(math.ceil(width / resolution)) + 1, int(math.ceil(depth / resolution)) + 1)
    origin = np.array([xmin - MARGIN, ymin - MARGIN])
    blocked = rasterise(triangles, origin, resolution, shape)
    for part in colliding:
        for tris in solids(part, band):
            _fill_solid(blocked, tris, origin, resolution)
    blocked |= underground(colliding, band, origin, resolution, shape)
    if not blocked.any():
        return None
    distance = ndimage.distance_transform_edt(~blocked) * resolution - resolution
    return ClearanceField(np.maximum(distance, 0.0), (float(origin[0]), float(origin[1])),
                          resolution)
