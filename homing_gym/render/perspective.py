"""Ordinary perspective camera views from the robot's camera (pinhole, no distortion).

The panoramic camera (:mod:`homing_gym.render.panorama`) is what the robot observes; a
perspective view is rendered on request (:meth:`homing_gym.env.HomingEnv.render_view`),
like the forward camera of Briggs et al. 2000 (Fig. 6: 640 x 480 and 320 x 240 images).
It changes nothing in the world, so it can be called in the middle of an episode.

Geometry: the camera sits ``camera_height`` metres above the floor at the robot's centre,
looks along the heading with zero pitch and roll; square pixels with focal length
``f = width / (2 tan(hfov/2))`` pixels. The value stored at pixel index ``(i, j)`` (column,
row) is the ray through image coordinate ``(i + c, j + c)`` with ``c = pixel_centre``
(0 for TinyRenderer, 0.5 for OpenGL/EGL, as measured for the panorama), so the bearing of
column index ``i`` is ``atan((width/2 - i - c) / f)`` (radians, CCW from the heading).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pybullet as p
from pybullet_utils.bullet_client import BulletClient

from homing_gym.render.panorama import DEFAULT_LIGHTING, Lighting, photometric


@dataclass(frozen=True)
class PerspectiveConfig:
    """Image ``width`` x ``height`` (pixels) and horizontal field of view ``hfov``
    (radians); ``near``/``far`` clipping distances (metres)."""

    width: int = 640
    height: int = 480
    hfov: float = math.radians(60)
    near: float = 0.02
    far: float = 30.0

    def __post_init__(self) -> None:
        for name in ("width", "height"):
            value = getattr(self, name)
            if not (isinstance(value, (int, np.integer)) and 16 <= value <= 4096):
                raise ValueError(f"perspective view {name} must be an integer in [16, 4096] "
                                 f"pixels, got {value!r}")
        if not (math.radians(5) <= self.hfov <= math.radians(150)):
            raise ValueError(f"hfov must lie in [5, 150] degrees (given in radians), got "
                             f"{self.hfov!r} rad = {math.degrees(self.hfov):.1f} deg")

    @property
    def focal(self) -> float:
        """Focal length in pixels."""
        return self.width / (2 * math.tan(self.hfov / 2))

    @property
    def vfov(self) -> float:
        """Vertical field of view (radians)."""
        return 2 * math.atan(self.height / (2 * self.focal))


#: Rays per pixel side of ray-cast perspective views (``3``: 3 x 3 rays averaged per
#: pixel, as a camera integrates light over its pixel). With one ray per pixel, fine
#: barcode stripes seen obliquely alias: Briggs' fast detector setting (320 x 240) missed
#: a landmark 2 m away at 45 degrees, and found it from 0 to 60 degrees with 3 x 3
#: (``docs/benchmark.md``: 2.2 ms -> 22 ms per 320 x 240 view). Panoramas stay at one
#: ray per pixel (``supersampling`` of :meth:`~homing_gym.render.raycast.RayCaster.panorama`).
VIEW_SUPERSAMPLING = 3


def render_perspective(client: BulletClient, pose, camera_height: float,
                       config: PerspectiveConfig = PerspectiveConfig(),
                       renderer: int = p.ER_TINY_RENDERER,
                       lighting: Lighting | None = None, caster=None) -> np.ndarray:
    """The view from ``pose = (x, y, yaw)`` (metres, radians) at ``camera_height``
    metres: uint8 ``(height, width, 3)``. ``lighting`` as for the panorama (``None``:
    the default), including its brightness/contrast change. With a ``caster``
    (:class:`~homing_gym.render.raycast.RayCaster`) the view is ray cast instead of rendered by
    PyBullet, :data:`VIEW_SUPERSAMPLING` squared rays per pixel spread evenly over it."""
    if caster is not None:
        return caster.perspective(pose, camera_height, config.width, config.height,
                                  config.focal, lighting, VIEW_SUPERSAMPLING)
    light = lighting or DEFAULT_LIGHTING
    x, y, yaw = float(pose[0]), float(pose[1]), float(pose[2])
    eye = [x, y, camera_height]
    target = [x + math.cos(yaw), y + math.sin(yaw), camera_height]
    view = client.computeViewMatrix(eye, target, [0, 0, 1])
    projection = p.computeProjectionMatrixFOV(
        fov=math.degrees(config.vfov), aspect=config.width / config.height,
        nearVal=config.near, farVal=config.far)
    _, _, rgba, _, _ = client.getCameraImage(
        config.width, config.height, view, projection, renderer=renderer, shadow=0,
        lightDirection=list(light.direction), lightAmbientCoeff=light.ambient,
        lightDiffuseCoeff=light.diffuse, lightSpecularCoeff=light.specular,
        flags=p.ER_NO_SEGMENTATION_MASK)
    img = np.asarray(rgba, dtype=np.uint8).reshape(config.height, config.width, 4)[..., :3]
    return photometric(np.ascontiguousarray(img), lighting)
