"""Teaching a robot its travel paths and work locations (Shiraishi & Sawasaki §3, §4).

What the paper's person teaches, done here by the env from the scene at teaching time:

* **Travel paths** (§3(1), §4(1), Fig. 4): along each path the robot records a
  *low-resolution panorama* every ``spacing`` = 0.47 m ("captured every 47 centimeters
  during travel"), "captured so that the center of the images is in the desired
  direction of travel". :func:`path_places` gives the places (also at each corner of
  the path and at its end: the last image is the one of the next work location), and
  :func:`teach_path` renders them.
* **Work locations** (§3(2), Fig. 2): a *multiresolution feature image map*
  (:class:`FeatureMap`): (1-1) the low-resolution panorama at the location, (1-2)
  high-resolution templates of characteristic points clipped from the full-resolution
  view, (1-3) their positions in the low-resolution panorama, with the points' 3-D
  indoor coordinates. The paper's person points at the characteristic points and
  enters their 3-D coordinates; here :func:`teach_work_location` takes them from the
  scene (``metadata["feature_points"]``: picture centres), keeping those the camera
  sees unoccluded from the location, and the coordinates are exact.

*Low resolution* is a grey-level image reduced by ``levels`` steps of OpenCV's Gaussian
pyramid (:func:`low_resolution`; each step halves width and height). All images are
panoramas of the env's camera (column ``x`` has bearing ``pi - 2*pi*x/W``), rendered
with the teaching-time lighting, as the env's goal snapshots are.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import cv2
import numpy as np

from homing_gym.render.panorama import bearing_column
from homing_gym.validation import require_positive
from homing_gym.vision import grey, low_resolution

#: ``snapshot(pose)``: the full-resolution panorama (RGB uint8) taken with the robot
#: standing at ``pose`` (x, y, yaw) under teaching-time lighting.
Snapshot = Callable[[np.ndarray], np.ndarray]
#: ``ray_hit(start, end)``: the first point a straight ray hits (3-D, metres), or None.
RayHit = Callable[[np.ndarray, np.ndarray], "np.ndarray | None"]

#: Distance (m) between taught places along a path (§4(1)).
PLACE_SPACING = 0.47


def path_places(points, spacing: float = PLACE_SPACING) -> np.ndarray:
    """Taught places ``(K, 3)`` = ``(x, y, yaw)`` along the polyline ``points`` (metres):
    one every ``spacing`` metres of path length from its start, plus every corner and
    the end (a place closer than ``spacing / 4`` before a corner or the end is dropped).
    The yaw is the desired direction of travel there: the direction of the leg that
    starts at the place (at the end, of the last leg)."""
    pts = np.asarray(points, dtype=np.float64)
    if pts.ndim != 2 or pts.shape[1] != 2 or len(pts) < 2:
        raise ValueError(f"a path needs at least two (x, y) points, got {points!r}")
    require_positive("spacing", spacing, "metres")
    legs = np.diff(pts, axis=0)
    lengths = np.hypot(legs[:, 0], legs[:, 1])
    if np.any(lengths < 1e-9):
        raise ValueError(f"path {points!r} repeats a point")
    cum = np.concatenate([[0.0], np.cumsum(lengths)])
    vertices = cum[1:]                                  # corners and the end
    regular = [s for s in np.arange(0.0, cum[-1], spacing)
               if not np.any((vertices - s > -1e-9) & (vertices - s < spacing / 4))]
    stations = np.unique(np.concatenate([regular, vertices]))
    leg = np.minimum(np.searchsorted(cum, stations, side="right") - 1, len(legs) - 1)
    xy = pts[leg] + legs[leg] * ((stations - cum[leg]) / lengths[leg])[:, None]
    yaw = np.arctan2(legs[leg, 1], legs[leg, 0])
    return np.column_stack([xy, yaw])


def teach_path(snapshot: Snapshot, points, levels: int,
               spacing: float = PLACE_SPACING) -> tuple[np.ndarray, np.ndarray]:
    """Low-resolution panoramas ``(K, h, w)`` uint8 at the places of :func:`path_places`,
    each centred on the desired direction of travel, and the places ``(K, 3)``."""
    places = path_places(points, spacing)
    images = np.stack([low_resolution(snapshot(pose), levels)
                       for pose in places])
    return images, places


@dataclass(frozen=True)
class FeatureMap:
    """A multiresolution feature image map (§3(2), Fig. 2) of a work location.

    ``panorama``: (1-1), the low-resolution grey panorama ``(h, w)`` at the location,
    centred on its heading. ``templates``: (1-2), ``(N, t, t)`` grey high-resolution
    templates, each centred exactly on its characteristic point. ``template_xy``: (1-3),
    ``(N, 2)`` continuous (column, row) of each point in ``panorama`` (multiply by
    ``2**levels`` for the full-resolution panorama). ``points``: ``(N, 3)`` the points'
    indoor coordinates (metres). ``pose``: the location ``(x, y, yaw)``. ``levels``:
    the pyramid steps between full and low resolution."""

    panorama: np.ndarray
    templates: np.ndarray
    template_xy: np.ndarray
    points: np.ndarray
    pose: np.ndarray
    levels: int


def point_direction(pose, point, camera_height: float) -> tuple[float, float, float]:
    """Bearing (radians, CCW from the heading), elevation (radians, up) and horizontal
    distance (metres) of the 3-D ``point`` from a camera at ``pose`` (x, y, yaw),
    ``camera_height`` metres above the floor."""
    dx, dy = point[0] - pose[0], point[1] - pose[1]
    dist = math.hypot(dx, dy)
    bearing = math.remainder(math.atan2(dy, dx) - pose[2], 2 * math.pi)
    return bearing, math.atan2(point[2] - camera_height, dist), dist


def clip_template(image: np.ndarray, x: float, y: float, size: int) -> np.ndarray:
    """The ``size x size`` patch of a grey panorama centred on the continuous point
    ``(x, y)`` (sub-pixel, bilinear; columns wrap around)."""
    pad = size
    padded = np.concatenate([image[:, -pad:], image, image[:, :pad]], axis=1)
    return cv2.getRectSubPix(padded, (size, size), (x - 0.5 + pad, y - 0.5))


def teach_work_location(snapshot: Snapshot, ray_hit: RayHit, camera_height: float,
                        vfov: float, pose, feature_points: dict, levels: int,
                        template_size: int = 17, max_points: int = 10,
                        distance_range: tuple[float, float] = (0.8, 6.0)) -> FeatureMap:
    """The feature map of the work location ``pose``: up to ``max_points`` of the scene's
    ``feature_points`` (``{name: (x, y, z)}``) that lie ``distance_range`` metres away,
    are unoccluded (a ray from the camera reaches them) and whose template lies inside
    the panorama's rows; chosen greedily to spread around the horizon (each next point
    the one farthest in bearing from those chosen). ``snapshot`` and ``ray_hit`` see the
    taught world (:data:`Snapshot`, :data:`RayHit`); ``camera_height`` in metres, ``vfov``
    the panorama's vertical field of view in radians."""
    pano = snapshot(pose)
    H, W = pano.shape[:2]
    half = (template_size // 2 + 1) * vfov / H
    candidates = []
    for name in sorted(feature_points):
        point = feature_points[name]
        bearing, elevation, dist = point_direction(pose, point, camera_height)
        if not (distance_range[0] <= dist <= distance_range[1]
                and abs(elevation) + half < vfov / 2 and _visible(ray_hit, pose, point, camera_height)):
            continue
        candidates.append((bearing, elevation, point))
    chosen: list[tuple[float, float, tuple]] = []
    while candidates and len(chosen) < max_points:
        def spread(c):
            return min((abs(math.remainder(c[0] - o[0], 2 * math.pi)) for o in chosen),
                       default=-abs(c[0]))
        best = max(candidates, key=spread)
        candidates.remove(best)
        chosen.append(best)
    image = grey(pano)
    templates, xy = [], []
    for bearing, elevation, _ in chosen:
        x = float(bearing_column(bearing, W))
        y = (vfov / 2 - elevation) / vfov * H
        templates.append(clip_template(image, x, y, template_size))
        xy.append((x / 2 ** levels, y / 2 ** levels))
    t = template_size
    return FeatureMap(
        panorama=low_resolution(pano, levels),
        templates=np.array(templates, np.uint8).reshape(-1, t, t),
        template_xy=np.array(xy, np.float32).reshape(-1, 2),
        points=np.array([c[2] for c in chosen], np.float32).reshape(-1, 3),
        pose=np.asarray(pose, np.float32), levels=levels)


def _visible(ray_hit: RayHit, pose, point, camera_height: float) -> bool:
    """Whether the straight line from the camera to ``point`` is free (the ray starts
    outside the robot body and may end within 3 cm of the point: the surface it is on)."""
    eye = np.array([pose[0], pose[1], camera_height])
    target = np.asarray(point, dtype=np.float64)
    length = float(np.linalg.norm(target - eye))
    start = eye + (target - eye) * (0.2 / length)
    hit = ray_hit(start, target)
    return hit is None or float(np.linalg.norm(hit - target)) < 0.03
