"""The ray-cast renderer (``renderer="raycast"``): one ray per pixel through the pixel
centre, intersected exactly with the scene's triangles (:mod:`homing_gym.render.worldmesh`) by
:func:`homing_gym.render.column_cast.cast_columns`.

Panorama rays follow the camera conventions of :mod:`homing_gym.render.panorama` exactly:
column ``j`` (centre ``j + 0.5``) has bearing ``pi - 2*pi*(j + 0.5)/W``
counter-clockwise from the heading, row ``i`` the elevation
``vfov/2 - vfov*(i + 0.5)/H``; no resampling. Perspective rays are those of an upright
pinhole with square pixels (:class:`~homing_gym.render.perspective.PerspectiveConfig`), through
pixel centres. Shading: the triangle's colour, times its texture if it has one (filtered
over a pixel's footprint by trilinear mip-mapping, as a camera pixel integrates light:
:func:`homing_gym.render.column_cast.shade`; each of a pixel's ``k x k`` rays filters over the
whole pixel, so their mean covers about a pixel and a half, like a pixel seen through
its lens' blur; with nearest texels distant textures aliased, and with each ray filtering
only its ``1/k`` share Hong's route following still lost targets on some seeds:
``docs/benchmark.md``), times ``ambient + diffuse * max(0, n . l)`` (Lambert with the
:class:`~homing_gym.render.panorama.Lighting` direction ``l``, ``n`` the face's normal on the
side the camera sees: a face turned away from the light gets the ambient term alone, as
in TinyRenderer, so walls of different orientation differ in brightness), clipped, then
the lighting's brightness/contrast change; rays that hit nothing see ``sky_color``, or
with a ``sky_zenith`` colour the blend of the two linear in the ray's elevation (the
horizon's colour at and below the horizon, the zenith's straight up). With
``supersampling = k`` each pixel averages ``k x k`` rays spread evenly over its area
(panoramas: ``CameraConfig.supersampling``, perspective views:
:data:`~homing_gym.render.perspective.VIEW_SUPERSAMPLING`). The
robot's own body is not part of the world mesh, so it never occludes the camera. The
same pose gives the same pixels.

Why not Embree: the ``embreex`` binding casts one ray at a time (5 million rays/s here,
2.4 ms for a 48 x 256 panorama, more than the whole env step budget); every camera here
is upright, so the rays of a column share one vertical plane, and casting column by
column gives the same exact hits several times faster (``docs/benchmark.md``). The tests
check pixel for pixel that both hit the same triangles.
"""

from __future__ import annotations

import threading
from functools import lru_cache
from typing import NamedTuple

import cv2
import numpy as np

from homing_gym.render.column_cast import cast_columns, lit_colors, shade, triangle_grid
from homing_gym.render.panorama import (DEFAULT_LIGHTING, CameraConfig, Lighting, column_bearing,
                                 photometric, row_elevation)
from homing_gym.render.shadows import ShadowMap, shadow_map
from homing_gym.render.worldmesh import WorldMesh

#: The shadow map of a caster without shadows (empty: ``shade`` skips the lookups).
_NO_SHADOWS = ShadowMap(np.zeros((0, 0)), np.eye(3), np.zeros(2), 1.0)
#: Largest texture atlas (bytes) kept in float64 rather than float32: the values are the
#: same, and the shader reads float64 without a conversion (textured panoramas about 12%
#: faster); a world with larger textures keeps float32, at half the memory.
ATLAS_FLOAT64_BYTES = 64 * 2**20
#: Each thread's scratch buffers (:func:`scratch_buffers`), shared by every caster, and
#: how many ray layouts a thread keeps them for.
_SCRATCH = threading.local()
SCRATCH_LAYOUTS = 8
#: Colour of rays that hit nothing (RGB in [0, 1]); TinyRenderer's background is white.
SKY_COLOR = (1.0, 1.0, 1.0)


def _centres(n: int, k: int) -> np.ndarray:
    """Positions (pixels) of the ``k`` evenly spread samples in each of ``n`` pixels,
    ``k*n`` of them in order: ``i + (a + 0.5)/k``."""
    return (np.arange(n * k) + 0.5) / k


class Rays(NamedTuple):
    """A camera's rays, and how they are laid out (derived once per camera, so that the
    caster need not check it for every image): ``beta (W,)`` column bearings (radians,
    counter-clockwise from the heading, descending); ``tan_elev (H, W)`` the tangent of
    each ray's elevation (descending down each column); ``circle``: the columns go once
    round the circle at even steps (a panorama); ``even_rows``: every column has the same
    rows, evenly spaced in elevation (a panorama); ``top_angle (W,)`` the elevation of
    each column's first row and ``rows_per_radian (W,)`` its rows per radian of elevation
    as if they were evenly spaced (where the caster's row searches start)."""

    beta: np.ndarray
    tan_elev: np.ndarray
    circle: bool
    even_rows: bool
    top_angle: np.ndarray
    rows_per_radian: np.ndarray


def camera_rays(beta: np.ndarray, tan_elev: np.ndarray) -> Rays:
    """:class:`Rays` of the columns ``beta`` and their rows' ``tan_elev``."""
    H, W = tan_elev.shape
    circle = W > 1 and bool(np.all(np.abs(-np.diff(beta) - 2 * np.pi / W) < 1e-9))
    elevation = np.arctan(tan_elev)
    top, span = elevation[0], elevation[0] - elevation[-1]
    per = np.divide(H - 1, span, out=np.zeros(W), where=span > 0)
    even = (per[0] * (top[0] - elevation[:, 0]) - np.arange(H)) if H > 1 else np.zeros(1)
    even_rows = bool(np.all(tan_elev == tan_elev[:, :1]) and np.all(np.abs(even) < 1e-6))
    return Rays(beta, np.asfortranarray(tan_elev), circle, even_rows, top, per)


@lru_cache(maxsize=32)
def panorama_rays(shape: tuple[int, int], vfov: float, k: int = 1) -> Rays:
    """The rays of the panorama's pixel centres (and ``k x k`` samples per pixel):
    ``k*W`` columns, ``k*H`` rows."""
    H, W = shape
    beta = column_bearing(_centres(W, k), W)
    tan = np.tan(row_elevation(_centres(H, k), H, vfov))
    return camera_rays(beta, np.broadcast_to(tan[:, None], (k * H, k * W)))


@lru_cache(maxsize=32)
def perspective_rays(width: int, height: int, focal: float, k: int = 1) -> Rays:
    """The rays of an upright pinhole camera along the heading (pixel centres
    ``(i + 0.5, j + 0.5)``, focal length in pixels)."""
    left = (width / 2 - _centres(width, k)) / focal
    up = (height / 2 - _centres(height, k)) / focal
    return camera_rays(np.arctan(left), up[:, None] / np.sqrt(1 + left[None, :] ** 2))


def mip_levels(texture: np.ndarray) -> list[np.ndarray]:
    """The mip pyramid of a texture (float RGB): full resolution, then each level the box
    average of the one before at half the size (``cv2.INTER_AREA``), down to one texel."""
    levels = [np.ascontiguousarray(texture, np.float32)]
    while max(levels[-1].shape[:2]) > 1:
        h, w = levels[-1].shape[:2]
        levels.append(cv2.resize(levels[-1], (max(1, w // 2), max(1, h // 2)),
                                 interpolation=cv2.INTER_AREA).reshape(max(1, h // 2),
                                                                       max(1, w // 2), 3))
    return levels


class TextureAtlas(NamedTuple):
    """Every mip level of every texture in one flat array, as :func:`shade` reads them:
    ``atlas`` the levels' RGB values (in [0, 1]) one after another, each with a border
    of one texel wrapped round from the opposite side
    (:func:`~homing_gym.render.column_cast.texel_offset`); ``levels[m] = (offset, height,
    width)`` of level ``m`` (its size without the border); texture ``k``'s levels from
    ``first_level[k]`` to ``first_level[k + 1]``."""

    atlas: np.ndarray
    levels: np.ndarray
    first_level: np.ndarray


def texture_atlas(textures: list[np.ndarray]) -> TextureAtlas:
    """The :class:`TextureAtlas` of ``textures`` (float RGB images): float32 values,
    stored as float64 where that takes at most :data:`ATLAS_FLOAT64_BYTES`."""
    pyramids = [mip_levels(t) for t in textures]
    images = [level for pyramid in pyramids for level in pyramid]
    bordered = [np.pad(i, ((1, 1), (1, 1), (0, 0)), mode="wrap") for i in images]
    offsets = np.concatenate([[0], np.cumsum([i.size for i in bordered])[:-1]]).astype(np.int64)
    atlas = (np.concatenate([i.ravel() for i in bordered]).astype(np.float32)
             if images else np.zeros(3, np.float32))
    levels = np.array([(o, i.shape[0], i.shape[1]) for o, i in zip(offsets, images)],
                      np.int64).reshape(-1, 3)
    first_level = np.concatenate([[0], np.cumsum([len(p) for p in pyramids])]).astype(np.int64)
    return TextureAtlas(atlas.astype(np.float64) if atlas.size * 8 <= ATLAS_FLOAT64_BYTES
                        else atlas, levels, first_level)


def scratch_buffers(H: int, W: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The caster's per-ray outputs for ``H x W`` rays (triangle index, barycentric
    weights) and its depth scratch: column-major, as the caster and the shader walk the
    image column by column. One set per thread and ray layout (the latest
    :data:`SCRATCH_LAYOUTS` layouts), shared by every caster of the thread: an image is
    cast and shaded before the next one begins, and each cast overwrites what the shader
    reads. A batch of envs stepping in one thread so reuses memory that stays in the
    cache, instead of a set of its own per env (1.8 MB at the default 96 x 512 rays)."""
    buffers = getattr(_SCRATCH, "buffers", None)
    if buffers is None:
        buffers = _SCRATCH.buffers = {}
    key = (H, W)
    if key not in buffers:
        if len(buffers) >= SCRATCH_LAYOUTS:
            del buffers[next(iter(buffers))]            # the oldest layout
        buffers[key] = (np.empty((W, H), np.int32).T, np.empty((W, H, 3)).transpose(1, 0, 2),
                        np.empty((W, H)))
    return buffers[key]


def texel_density(mesh: WorldMesh) -> np.ndarray:
    """Texels per metre of each triangle's texture at full resolution (``(N,)``; 0 for
    untextured triangles): the square root of the texels its UVs cover over its area."""
    density = np.zeros(len(mesh.triangles))
    textured = np.flatnonzero(mesh.texture >= 0)
    if len(textured) == 0:
        return density
    tris = mesh.triangles[textured].astype(np.float64)
    area = 0.5 * np.linalg.norm(np.cross(tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0]), axis=1)
    uv = mesh.uvs[textured].astype(np.float64)
    e1, e2 = uv[:, 1] - uv[:, 0], uv[:, 2] - uv[:, 0]
    uv_area = 0.5 * np.abs(e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0])
    sizes = np.array([t.shape[0] * t.shape[1] for t in mesh.textures], np.float64)
    texels = uv_area * sizes[mesh.texture[textured]]
    density[textured] = np.sqrt(texels / np.maximum(area, 1e-12))
    return density


class RayCaster:
    """Casts and shades rays in one world mesh; rebuilt when the world changes."""

    def __init__(self, mesh: WorldMesh, sky_color=SKY_COLOR, shadows: bool = False,
                 sky_zenith=None):
        if len(mesh.triangles) == 0:
            raise ValueError("the world mesh has no triangles")
        if not np.all(np.isfinite(mesh.triangles)):
            raise ValueError("the world mesh has non-finite vertices")
        self.mesh = mesh
        self.sky = np.asarray(sky_color, np.float64)
        #: The sky straight up (RGB), or None: a uniform sky.
        self.sky_zenith = None if sky_zenith is None else np.asarray(sky_zenith, np.float64)
        self._skies: dict[int, tuple[Rays, np.ndarray]] = {}
        self._tris = mesh.triangles.astype(np.float64)
        self._normals = mesh.normals.astype(np.float64)
        self._closed = mesh.closed.astype(np.bool_)
        #: The triangles as the caster reads them (in the mesh's float32: exact, and half
        #: the memory to read for every image), grouped by cell where dense enough to cull.
        self._triangles = triangle_grid(mesh.triangles, mesh.normals, mesh.closed)
        self._uvs = mesh.uvs.astype(np.float64)
        self._texture = mesh.texture.astype(np.int64)
        #: Triangles whose hits need barycentric weights (a texture; with shadows, all).
        self._textured = self._texture >= 0
        self._everywhere = np.ones(len(self._texture), np.bool_)
        self._atlas, self._levels, self._first_level = texture_atlas(mesh.textures)
        self._texel_density = texel_density(mesh)
        #: Cast shadows (:mod:`homing_gym.render.shadows`); maps cached per light direction.
        self.shadows = shadows
        self._shadow_maps: dict[tuple, ShadowMap] = {}
        #: Lit triangle colours (:meth:`_lit`), for the light ``_lit_key``.
        self._lit_colors = np.empty((len(self._tris), 3))
        self._lit_key: tuple | None = None
        self._light = np.zeros(3)            # the unit light direction of ``_lit_key``
        self._all = np.arange(len(self._tris))
        self._drawn = np.empty(len(self._tris), np.int64)    # the caster's drawn triangles

    def _shadow_map(self, lighting: Lighting) -> ShadowMap:
        key = tuple(lighting.direction)
        if key not in self._shadow_maps:
            self._shadow_maps[key] = shadow_map(self._tris, lighting.direction)
        return self._shadow_maps[key]

    def _lit(self, light: Lighting, origin: np.ndarray, drawn: np.ndarray) -> np.ndarray:
        """The lit colours (:func:`lit_colors`) of the triangles the image shows seen
        from ``origin``: those of closed solids computed once per light, the open ones
        among ``drawn`` (those the caster drew) for every image."""
        key = (tuple(light.direction), light.ambient, light.diffuse)
        which = drawn[~self._closed[drawn]]
        if self._lit_key != key:
            direction = np.asarray(light.direction, np.float64)
            self._lit_key, self._light = key, direction / np.linalg.norm(direction)
            which = self._all
        lit_colors(self.mesh.colors, self._normals, self._tris, self._closed, self._light,
                   light.ambient, light.diffuse, origin, which, self._lit_colors)
        return self._lit_colors

    def _sky(self, rays: Rays) -> np.ndarray:
        """The sky colour of each of ``rays`` as :func:`shade` reads it: ``(1, 1, 3)``
        when uniform, ``(H, 1, 3)`` for a panorama's even rows, else ``(H, W, 3)``; kept
        per ray layout."""
        if self.sky_zenith is None:
            return self.sky.reshape(1, 1, 3)
        if id(rays) not in self._skies:
            tan = rays.tan_elev[:, :1] if rays.even_rows else rays.tan_elev
            up = np.clip(np.arctan(tan) / (np.pi / 2), 0.0, 1.0)[..., None]
            sky = np.ascontiguousarray(self.sky * (1 - up) + self.sky_zenith * up)
            self._skies[id(rays)] = (rays, sky)        # the rays kept: their id stays theirs
        return self._skies[id(rays)][1]

    def _image(self, pose, camera_height: float, rays: Rays, k: int, spacing: float,
               lighting: Lighting | None) -> np.ndarray:
        x, y, yaw = (float(v) for v in pose)
        H, W = rays.tan_elev.shape
        hit, weights, depth = scratch_buffers(H, W)
        origin = np.array([x, y, camera_height])
        weighted = self._everywhere if self.shadows else self._textured
        drawn = self._drawn[:cast_columns(*self._triangles, origin, yaw, *rays, weighted, hit,
                                          weights, depth, self._drawn)]
        image = np.empty((H // k, W // k, 3), np.uint8)
        light = lighting or DEFAULT_LIGHTING
        shadow = self._shadow_map(light) if self.shadows else _NO_SHADOWS
        shade(hit, weights, self._lit(light, origin, drawn), self._texture,
              self._uvs, self._atlas, self._levels, self._first_level, self._texel_density,
              self._tris, self._normals, origin, spacing, self._sky(rays), image,
              self.mesh.colors * light.ambient if self.shadows else self.mesh.colors,
              shadow.depth, shadow.axes, shadow.origin, shadow.cell)
        return photometric(image, lighting)

    def panorama(self, pose, camera_height: float, config: CameraConfig,
                 lighting: Lighting | None = None, supersampling: int | None = None) -> np.ndarray:
        """The cylindrical panorama (uint8 ``(H, W, 3)``) at ``pose = (x, y, yaw)``;
        ``supersampling`` defaults to ``config.supersampling``."""
        k = config.supersampling if supersampling is None else supersampling
        H, W = config.panorama_shape
        rays = panorama_rays((H, W), config.vfov, k)
        # each ray filters the texture over a whole pixel (see :func:`shade`'s caller note)
        spacing = max(2 * np.pi / W, config.vfov / H)
        return self._image(pose, camera_height, rays, k, spacing, lighting)

    def perspective(self, pose, camera_height: float, width: int, height: int, focal: float,
                    lighting: Lighting | None = None, supersampling: int = 1) -> np.ndarray:
        """A pinhole view (uint8 ``(height, width, 3)``) along the heading at ``pose``."""
        rays = perspective_rays(width, height, float(focal), supersampling)
        return self._image(pose, camera_height, rays, supersampling, 1.0 / focal, lighting)
