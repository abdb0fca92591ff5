"""The panoramic camera: cylindrical panorama, catadioptric ring image, horizon signature.

Conventions (tested in ``tests/homing_gym/test_panorama.py``):

* Panorama: uint8 ``(H, W, 3)``, the full 360 degrees. The continuous column coordinate
  ``x`` runs over ``[0, W)``; pixel column ``j`` covers ``[j, j + 1)``, centre ``j + 0.5``.
  Bearing (radians, counter-clockwise from the robot's heading)
  ``beta(x) = pi - 2*pi*x/W``: straight ahead at ``x = W/2``, the robot's left
  (``beta = pi/2``) at ``x = W/4``, left of centre; directly behind at ``x = 0`` (= ``W``).
* Rows are equiangular in elevation: ``elevation(y) = vfov/2 - vfov*y/H`` for the
  continuous row coordinate ``y`` in ``[0, H)``; the horizon is at ``y = H/2``, the
  boundary between rows ``H/2 - 1`` and ``H/2``. The default vertical field of view is
  60 degrees (+-30 about the horizon).
* ``omni`` ring image (square ``S x S``), what a camera looking at a convex mirror sees
  (Hong et al. 1991 §2, Yu & Kim §III), drawn as seen from above: the robot's heading points
  up (towards row 0), bearings run counter-clockwise in the image, elevation grows with the
  radius from ``-vfov/2`` at ``r_in = 0.25*S/2`` to ``+vfov/2`` at ``r_out = 0.98*S/2``;
  the horizon is the circle of radius ``(r_in + r_out)/2`` about the image centre
  ``(S/2, S/2)``. Outside the ring the image is black.
* ``signature``: Hong 1991 §2's one-dimensional location signature, one value per column,
  the luminance in ``[0, 1]`` averaged over ``signature_rows`` samples spaced one row apart
  and centred on the horizon (linear interpolation between rows).

By default (``renderer="raycast"``) the panorama is ray cast directly
(:mod:`homing_gym.render.raycast`). With ``"tiny"`` or ``"egl"`` it is rendered by PyBullet from
``n_views`` perspective cameras at the camera centre, facing evenly spaced yaws, and
resampled into the cylinder with a single precomputed ``cv2.remap``. The renderers give
the same geometry; their shading and background colour differ, so do not mix them
between training and evaluation (result files record the renderer).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import cv2
import numpy as np
import pybullet as p
from pybullet_utils.bullet_client import BulletClient

from homing_gym.scenes.appearance import Appearance
from homing_gym.validation import require_number
from homing_gym.vision import horizon_line

RENDERERS = ("tiny", "egl", "raycast")
#: Allowed panorama heights and widths (pixels, inclusive) and numbers of perspective views.
PANORAMA_HEIGHTS, PANORAMA_WIDTHS = (8, 1024), (16, 4096)
N_VIEWS = (3, 4, 6, 8)
PANORAMA_SHAPES = (f"(H, W) integers with {PANORAMA_HEIGHTS[0]} <= H <= {PANORAMA_HEIGHTS[1]} "
                   f"and {PANORAMA_WIDTHS[0]} <= W <= {PANORAMA_WIDTHS[1]}")
OMNI_INNER, OMNI_OUTER = 0.25, 0.98


def column_bearing(x, width: int):
    """Bearing (radians, CCW from heading) of continuous column coordinate ``x``."""
    return np.pi - 2 * np.pi * np.asarray(x, dtype=np.float64) / width


def bearing_column(beta, width: int):
    """Continuous column coordinate in ``[0, W)`` of bearing ``beta`` (radians, CCW)."""
    return np.mod((np.pi - np.asarray(beta, dtype=np.float64)) * width / (2 * np.pi), width)


def row_elevation(y, height: int, vfov: float):
    """Elevation (radians, up positive) of continuous row coordinate ``y``."""
    return vfov / 2 - vfov * np.asarray(y, dtype=np.float64) / height


@dataclass(frozen=True)
class CameraConfig:
    """Panoramic camera settings.

    ``panorama_shape`` is ``(H, W)`` in pixels; the angular resolution is ``360/W`` degrees
    per column (default 1.41 deg; ``W = 360`` gives 1 deg) and ``vfov/H`` per row (default
    1.25 deg). ``n_views`` perspective renders are resampled; 6 was the fastest of 4, 6, 8
    for the default shape (``python -m homing_gym.benchmark``).
    ``vfov`` is the full vertical field of view in radians, symmetric about the horizon.
    ``supersampling`` (``renderer="raycast"``): ``k x k`` rays averaged per pixel, 1-4.
    The default 2 is what a camera does (it integrates light over its pixel): with one ray
    per pixel the landmark edges alias, and Hong's snapshot homing found the home
    direction within 30 degrees in 14 of 24 rendered arena pairs (15 with TinyRenderer
    and with 2 x 2) and Bekris' long-range homing did not turn to the home heading; the
    cost is in ``docs/benchmark.md``.
    """

    panorama_shape: tuple[int, int] = (48, 256)
    vfov: float = math.radians(60)
    n_views: int = 6
    near: float = 0.02
    far: float = 30.0
    omni_size: int = 128
    signature_rows: int = 5
    renderer: str = "raycast"
    supersampling: int = 2

    def __post_init__(self) -> None:
        shape = self.panorama_shape
        if (len(shape) != 2 or not all(isinstance(v, (int, np.integer)) for v in shape)
                or not (PANORAMA_HEIGHTS[0] <= shape[0] <= PANORAMA_HEIGHTS[1]
                        and PANORAMA_WIDTHS[0] <= shape[1] <= PANORAMA_WIDTHS[1])):
            raise ValueError(f"panorama_shape must be {PANORAMA_SHAPES}, got {shape!r}")
        if not (math.radians(10) <= self.vfov <= math.radians(120)):
            raise ValueError(f"vfov must lie in [10, 120] degrees (given in radians), got "
                             f"{self.vfov!r} rad = {math.degrees(self.vfov):.1f} deg")
        if not isinstance(self.n_views, (int, np.integer)) or isinstance(self.n_views, bool) \
                or self.n_views not in N_VIEWS:
            raise ValueError(f"n_views must be one of {N_VIEWS}, got {self.n_views!r}")
        require_number("omni_size", self.omni_size, 16, 2048, "pixels", integer=True)
        if not (1 <= self.signature_rows <= shape[0] - 2):
            raise ValueError(f"signature_rows must be in [1, H - 2] = [1, {shape[0] - 2}], "
                             f"got {self.signature_rows!r}")
        require_number("supersampling", self.supersampling, 1, 4, "rays per pixel side",
                       integer=True)
        if self.renderer not in RENDERERS:
            raise ValueError(f"unknown renderer {self.renderer!r}; allowed: {RENDERERS}")
        if not (0 < self.near < self.far):
            raise ValueError(f"need 0 < near < far, got near={self.near!r}, far={self.far!r}")


@dataclass(frozen=True)
class Lighting:
    """Scene lighting of a render: ``direction`` towards the light (world frame), the
    renderer's ambient/diffuse/specular coefficients, and a global photometric change
    applied to the picture, ``out = contrast*(in - 127.5) + 127.5 + brightness``."""

    direction: tuple[float, float, float] = (0.4, 0.3, 1.0)
    ambient: float = 0.6
    diffuse: float = 0.45
    specular: float = 0.05
    brightness: float = 0.0
    contrast: float = 1.0


def random_lighting(rng: np.random.Generator, strength: float) -> Lighting:
    """A changed lighting drawn from ``rng``: light azimuth anywhere, elevation 20-80
    degrees, brightness within +-60*strength grey levels, contrast within
    1 +- 0.4*strength, diffuse/ambient balance shifted by up to 0.2*strength."""
    azimuth = rng.uniform(-np.pi, np.pi)
    elevation = rng.uniform(np.radians(20), np.radians(80))
    shift = rng.uniform(-0.2, 0.2) * strength
    return Lighting(
        direction=(math.cos(elevation) * math.cos(azimuth),
                   math.cos(elevation) * math.sin(azimuth), math.sin(elevation)),
        ambient=0.6 - shift, diffuse=0.45 + shift,
        brightness=float(rng.uniform(-60, 60) * strength),
        contrast=float(1 + rng.uniform(-0.4, 0.4) * strength))


DEFAULT_LIGHTING = Lighting()


def world_lighting(appearance: Appearance) -> Lighting | None:
    """The lighting of a world's :class:`~homing_gym.scenes.appearance.Appearance`
    (its light's direction, ambient and diffuse terms), ``None`` where it has no light
    of its own (the renderers' default)."""
    if appearance.light_direction is None:
        return None
    return Lighting(direction=appearance.light_direction, ambient=appearance.ambient,
                    diffuse=appearance.diffuse)


def photometric(image: np.ndarray, lighting: Lighting | None) -> np.ndarray:
    """``image`` (uint8) under the global brightness/contrast change of ``lighting``
    (unchanged for ``None`` or no change)."""
    if lighting is None or (lighting.contrast == 1 and lighting.brightness == 0):
        return image
    offset = 127.5 * (1 - lighting.contrast) + lighting.brightness
    return cv2.addWeighted(image, lighting.contrast, image, 0.0, offset)


@dataclass(frozen=True)
class ViewGeometry:
    """Size and intrinsics of the perspective views the panorama is resampled from."""

    width: int
    height: int
    focal: float
    yaws: tuple[float, ...]

    @property
    def vfov_degrees(self) -> float:
        return math.degrees(2 * math.atan(self.height / 2 / self.focal))


def view_geometry(config: CameraConfig) -> ViewGeometry:
    """Perspective views with square pixels, at least as dense as the panorama at their
    centre, covering their azimuth sector plus a 2-pixel margin for interpolation."""
    H, W = config.panorama_shape
    n = config.n_views
    focal = max(W / (2 * np.pi), H / config.vfov)
    half_h = np.pi / n + 2.0 / focal
    width = 2 * math.ceil(focal * math.tan(half_h))
    height = 2 * math.ceil(focal * math.tan(config.vfov / 2) / math.cos(np.pi / n) + 2)
    yaws = tuple(2 * np.pi * k / n for k in range(n))
    return ViewGeometry(width=width, height=height, focal=focal, yaws=yaws)


def panorama_maps(config: CameraConfig, geom: ViewGeometry,
                  pixel_centre: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """``cv2.remap`` maps from the side-by-side views ``(h, n*w)`` to the panorama ``(H, W)``.

    ``pixel_centre`` is where the renderer samples pixel ``i``: at image coordinate
    ``i + pixel_centre``. TinyRenderer samples at ``i`` (0.0), OpenGL (EGL) at ``i + 0.5``;
    both measured with the pole test of ``tests/homing_gym/test_panorama.py``.
    """
    H, W = config.panorama_shape
    beta = column_bearing(np.arange(W) + 0.5, W)[None, :].repeat(H, 0)
    elev = row_elevation(np.arange(H) + 0.5, H, config.vfov)[:, None].repeat(W, 1)
    n = config.n_views
    view = np.mod(np.round(beta / (2 * np.pi / n)), n).astype(int)
    rel = beta - np.asarray(geom.yaws)[view]
    # direction in the view's frame: forward, left, up
    fwd = np.cos(elev) * np.cos(rel)
    left = np.cos(elev) * np.sin(rel)
    up = np.sin(elev)
    u = geom.width / 2 - geom.focal * left / fwd - pixel_centre
    v = geom.height / 2 - geom.focal * up / fwd - pixel_centre
    map_x = (u + view * geom.width).astype(np.float32)
    map_y = v.astype(np.float32)
    return map_x, map_y


def omni_maps(config: CameraConfig) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``cv2.remap`` maps from the column-padded panorama ``(H, W + 2)`` to the ring image,
    and the boolean mask of ring pixels."""
    H, W = config.panorama_shape
    S = config.omni_size
    c = (np.arange(S) + 0.5) - S / 2
    dx, dy = np.meshgrid(c, c)
    r = np.hypot(dx, dy)
    r_in, r_out = OMNI_INNER * S / 2, OMNI_OUTER * S / 2
    beta = np.arctan2(-dx, -dy)
    elev = -config.vfov / 2 + config.vfov * (r - r_in) / (r_out - r_in)
    x = bearing_column(beta, W)
    y = (config.vfov / 2 - elev) / config.vfov * H
    mask = (r >= r_in) & (r <= r_out)
    return (x - 0.5 + 1).astype(np.float32), (y - 0.5).astype(np.float32), mask


def omni_horizon_radius(omni_size: int) -> float:
    """Radius (pixels) of the horizon circle in the ``omni`` ring image."""
    return (OMNI_INNER + OMNI_OUTER) / 2 * omni_size / 2


def signature_weights(height: int, rows: int) -> np.ndarray:
    """Row weights (sum 1) that average ``rows`` samples one row apart centred on the
    horizon ``y = H/2``, each sample linearly interpolated between pixel rows."""
    weights = np.zeros(height)
    for k in range(rows):
        y = height / 2 + k - (rows - 1) / 2 - 0.5       # sample position in row-centre units
        lo = math.floor(y)
        frac = y - lo
        weights[lo] += 1 - frac
        weights[min(lo + 1, height - 1)] += frac
    return (weights / rows).astype(np.float32)


#: Corners closer than this (metres) to the plane through a perspective view's eye,
#: perpendicular to its direction, make TinyRenderer hang (their ``w`` is 0 in float32).
DEGENERATE_DEPTH = 1e-6
#: How far (metres) :func:`safe_eye` moves such an eye back along its view.
EYE_SHIFT = 1e-4


def safe_eye(eye: tuple[float, float, float], direction: tuple[float, float],
             vertices: np.ndarray | None) -> tuple[float, float]:
    """The ``(x, y)`` of a perspective view's eye, moved :data:`EYE_SHIFT` back along the
    horizontal view ``direction`` (unit) when a world corner lies in the plane through the
    eye perpendicular to it. There PyBullet's TinyRenderer never returns (found at the
    house's grid pose (6.2, 1.1) looking along -y, where a wall's end face lies in that
    plane: its corners project with ``w = 0``); 0.1 mm changes nothing visible, and every
    other view keeps its exact eye."""
    if vertices is not None and len(vertices):
        depth = ((vertices[:, 0] - eye[0]) * direction[0]
                 + (vertices[:, 1] - eye[1]) * direction[1])
        if np.any(np.abs(depth) < DEGENERATE_DEPTH):
            return eye[0] - EYE_SHIFT * direction[0], eye[1] - EYE_SHIFT * direction[1]
    return eye[0], eye[1]


class PanoramaCamera:
    """Renders panoramas at a robot pose and derives the ``omni`` and ``signature`` views."""

    def __init__(self, config: CameraConfig = CameraConfig(), camera_height: float = 0.30,
                 renderer: int = p.ER_TINY_RENDERER, caster=None, vertices=None):
        """``renderer``: PyBullet's renderer for the perspective views; ``caster``: a
        callable returning the simulator's current
        :class:`~homing_gym.render.raycast.RayCaster`, which then renders instead; ``vertices``:
        a callable returning the world's triangle corners ``(V, 3)``, so that PyBullet's
        views avoid the poses at which TinyRenderer never returns (:func:`safe_eye`)."""
        self.config = config
        self.caster = caster
        self.vertices = vertices
        self.camera_height = camera_height
        self.renderer = renderer
        self.geometry = view_geometry(config)
        centre = 0.5 if renderer == p.ER_BULLET_HARDWARE_OPENGL else 0.0
        self._map_x, self._map_y = panorama_maps(config, self.geometry, centre)
        self._omni_x, self._omni_y, self._omni_mask = omni_maps(config)
        self._sig_weights = signature_weights(config.panorama_shape[0], config.signature_rows)
        g = self.geometry
        self._views = np.empty((g.height, g.width * config.n_views, 3), np.uint8)
        self._projection = p.computeProjectionMatrixFOV(
            fov=g.vfov_degrees, aspect=g.width / g.height, nearVal=config.near,
            farVal=config.far)

    @property
    def shape(self) -> tuple[int, int, int]:
        return (*self.config.panorama_shape, 3)

    def render_views(self, client: BulletClient, pose,
                     lighting: Lighting = DEFAULT_LIGHTING) -> np.ndarray:
        """The ``n_views`` perspective images side by side, uint8 ``(h, n*w, 3)``."""
        g = self.geometry
        x, y, yaw = float(pose[0]), float(pose[1]), float(pose[2])
        vertices = self.vertices() if self.vertices is not None else None
        for k, view_yaw in enumerate(g.yaws):
            a = yaw + view_yaw
            direction = (math.cos(a), math.sin(a))
            ex, ey = safe_eye((x, y, self.camera_height), direction, vertices)
            target = [ex + direction[0], ey + direction[1], self.camera_height]
            view = client.computeViewMatrix([ex, ey, self.camera_height], target, [0, 0, 1])
            _, _, rgba, _, _ = client.getCameraImage(
                g.width, g.height, view, self._projection, renderer=self.renderer,
                shadow=0, lightDirection=list(lighting.direction),
                lightAmbientCoeff=lighting.ambient, lightDiffuseCoeff=lighting.diffuse,
                lightSpecularCoeff=lighting.specular, flags=p.ER_NO_SEGMENTATION_MASK)
            rgba = np.asarray(rgba, dtype=np.uint8).reshape(g.height, g.width, 4)
            self._views[:, k * g.width:(k + 1) * g.width] = rgba[..., :3]
        return self._views

    def render(self, client: BulletClient, pose, lighting: Lighting | None = None) -> np.ndarray:
        """Panorama at ``pose = (x, y, yaw)`` (metres, radians): uint8 ``(H, W, 3)``,
        under ``lighting`` (``None``: the default lighting)."""
        if self.caster is not None:
            return self.caster().panorama(pose, self.camera_height, self.config, lighting)
        views = self.render_views(client, pose, lighting or DEFAULT_LIGHTING)
        pano = cv2.remap(views, self._map_x, self._map_y, cv2.INTER_LINEAR,
                         borderMode=cv2.BORDER_REPLICATE)
        return photometric(pano, lighting)

    def omni(self, panorama: np.ndarray) -> np.ndarray:
        """The catadioptric ring image of a panorama: uint8 ``(S, S, 3)``."""
        padded = np.concatenate([panorama[:, -1:], panorama, panorama[:, :1]], axis=1)
        ring = cv2.remap(padded, self._omni_x, self._omni_y, cv2.INTER_LINEAR,
                         borderMode=cv2.BORDER_REPLICATE)
        ring[~self._omni_mask] = 0
        return ring

    def signature(self, panorama: np.ndarray) -> np.ndarray:
        """Hong 1991 §2 horizon signature: float32 ``(W,)`` luminance in ``[0, 1]``."""
        return horizon_line(panorama, self._sig_weights)
