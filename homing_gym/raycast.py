"""The ray-cast renderer (``renderer="raycast"``): one ray per pixel through the pixel
centre, cast with Intel Embree (the ``embreex`` binding) into the scene's triangles
(:mod:`homing_gym.worldmesh`).

Panorama rays follow the camera conventions of :mod:`homing_gym.panorama` exactly:
column ``j`` (centre ``j + 0.5``) has bearing ``pi - 2*pi*(j + 0.5)/W``
counter-clockwise from the heading, row ``i`` the elevation
``vfov/2 - vfov*(i + 0.5)/H``; no resampling. Perspective rays are those of a pinhole
with square pixels (:class:`~homing_gym.perspective.PerspectiveConfig`), through pixel
centres. Shading: the triangle's colour, times its texture (nearest texel) if it has one,
times ``ambient + diffuse * |n . l|`` (two-sided Lambert with the
:class:`~homing_gym.panorama.Lighting` direction), clipped, then the lighting's
brightness/contrast change; rays that hit nothing see ``sky_color``. With
``supersampling = k`` each pixel averages ``k x k`` rays spread over its area. The
robot's own body is not part of the world mesh, so it never occludes the camera. The
same pose gives the same pixels.
"""

from __future__ import annotations

import math
from functools import lru_cache

import numpy as np

from homing_gym.panorama import (DEFAULT_LIGHTING, CameraConfig, Lighting, column_bearing,
                                 photometric, row_elevation)
from homing_gym.worldmesh import WorldMesh

#: Colour of rays that hit nothing (RGB in [0, 1]); TinyRenderer's background is white.
SKY_COLOR = (1.0, 1.0, 1.0)


def _embree():
    try:
        from embreex import rtcore_scene
        from embreex.mesh_construction import TriangleMesh
    except ImportError as err:  # an exotic platform without embreex wheels
        raise ValueError(f'renderer="raycast" needs the embreex package ({err}); install '
                         f'it with `pip install embreex`, or use renderer="tiny"') from None
    return rtcore_scene, TriangleMesh


def _offsets(k: int) -> np.ndarray:
    """Sub-pixel sample offsets in ``(-0.5, 0.5)``, ``k x k`` of them (``(0, 0)`` for 1)."""
    grid = (np.arange(k) + 0.5) / k - 0.5
    return np.stack(np.meshgrid(grid, grid, indexing="ij"), -1).reshape(-1, 2)


@lru_cache(maxsize=32)
def panorama_directions(shape: tuple[int, int], vfov: float, k: int = 1) -> np.ndarray:
    """Unit ray directions ``(k*k, H, W, 3)`` in the robot frame (x ahead, y left, z up)
    of the panorama's pixel centres (and ``k x k`` sub-pixel samples)."""
    H, W = shape
    out = []
    for dy, dx in _offsets(k):
        beta = column_bearing(np.arange(W) + 0.5 + dx, W)[None, :]
        elev = row_elevation(np.arange(H) + 0.5 + dy, H, vfov)[:, None]
        out.append(np.stack(np.broadcast_arrays(np.cos(elev) * np.cos(beta),
                                                np.cos(elev) * np.sin(beta),
                                                np.sin(elev) + 0 * beta), -1))
    return np.array(out, np.float32)


@lru_cache(maxsize=32)
def perspective_directions(width: int, height: int, focal: float, k: int = 1) -> np.ndarray:
    """Unit ray directions ``(k*k, height, width, 3)`` (robot frame) of a pinhole camera
    looking along the heading, through pixel centres ``(i + 0.5, j + 0.5)``."""
    out = []
    for dy, dx in _offsets(k):
        left = (width / 2 - (np.arange(width) + 0.5 + dx)) / focal
        up = (height / 2 - (np.arange(height) + 0.5 + dy)) / focal
        d = np.stack(np.broadcast_arrays(np.ones((height, width)), left[None, :],
                                         up[:, None]), -1)
        out.append(d / np.linalg.norm(d, axis=-1, keepdims=True))
    return np.array(out, np.float32)


class RayCaster:
    """Casts and shades rays in one world mesh; rebuilt when the world changes."""

    def __init__(self, mesh: WorldMesh, sky_color=SKY_COLOR):
        rtcore_scene, TriangleMesh = _embree()
        if len(mesh.triangles) == 0:
            raise ValueError("the world mesh has no triangles")
        if not np.all(np.isfinite(mesh.triangles)):
            raise ValueError("the world mesh has non-finite vertices")
        self.mesh = mesh
        self._scene = rtcore_scene.EmbreeScene()
        TriangleMesh(self._scene, mesh.triangles)
        self._normals = mesh.normals.astype(np.float32)
        self.sky = np.asarray(sky_color, np.float32)

    def _shade(self, origin: np.ndarray, dirs: np.ndarray, lighting: Lighting) -> np.ndarray:
        """Colours ``(n, 3)`` in ``[0, 1]`` of rays from ``origin`` along ``dirs (n, 3)``."""
        n = len(dirs)
        origins = np.broadcast_to(origin.astype(np.float32), (n, 3))
        hit = self._scene.run(np.ascontiguousarray(origins), np.ascontiguousarray(dirs),
                              output=1)
        prim = hit["primID"]
        ok = prim >= 0
        out = np.empty((n, 3), np.float32)
        out[~ok] = self.sky
        p = prim[ok]
        color = self.mesh.colors[p]                # fancy indexing: a copy
        tex = self.mesh.texture[p]
        if np.any(tex >= 0):
            u, v = hit["u"][ok], hit["v"][ok]
            uv = self.mesh.uvs[p]
            st = (1 - u - v)[:, None] * uv[:, 0] + u[:, None] * uv[:, 1] + v[:, None] * uv[:, 2]
            for t in np.unique(tex[tex >= 0]):
                sel = tex == t
                image = self.mesh.textures[t]
                h, w = image.shape[:2]
                col = np.clip((st[sel, 0] % 1.0) * w, 0, w - 1).astype(np.int64)
                row = np.clip((1.0 - st[sel, 1] % 1.0) * h, 0, h - 1).astype(np.int64)
                color[sel] *= image[row, col]
        light = np.asarray(lighting.direction, np.float32)
        light = light / np.linalg.norm(light)
        lambert = np.abs(self._normals[p] @ light)
        out[ok] = np.clip(color * (lighting.ambient + lighting.diffuse * lambert)[:, None], 0, 1)
        return out

    def _image(self, pose, camera_height: float, dirs: np.ndarray,
               lighting: Lighting | None) -> np.ndarray:
        """Render ``dirs (k*k, H, W, 3)`` (robot frame) from the camera at ``pose``."""
        x, y, yaw = (float(v) for v in pose)
        c, s = math.cos(yaw), math.sin(yaw)
        rot = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]], np.float32)
        samples, H, W, _ = dirs.shape
        world = dirs.reshape(-1, 3) @ rot.T
        colors = self._shade(np.array([x, y, camera_height]), world,
                             lighting or DEFAULT_LIGHTING)
        image = colors.reshape(samples, H, W, 3).mean(axis=0)
        return photometric((image * 255 + 0.5).astype(np.uint8), lighting)

    def panorama(self, pose, camera_height: float, config: CameraConfig,
                 lighting: Lighting | None = None, supersampling: int = 1) -> np.ndarray:
        """The cylindrical panorama (uint8 ``(H, W, 3)``) at ``pose = (x, y, yaw)``."""
        dirs = panorama_directions(tuple(config.panorama_shape), config.vfov, supersampling)
        return self._image(pose, camera_height, dirs, lighting)

    def perspective(self, pose, camera_height: float, width: int, height: int, focal: float,
                    lighting: Lighting | None = None, supersampling: int = 1) -> np.ndarray:
        """A pinhole view (uint8 ``(height, width, 3)``) along the heading at ``pose``."""
        dirs = perspective_directions(width, height, float(focal), supersampling)
        return self._image(pose, camera_height, dirs, lighting)


def is_available() -> bool:
    """Whether ``embreex`` can be imported here."""
    try:
        _embree()
    except ValueError:
        return False
    return True
