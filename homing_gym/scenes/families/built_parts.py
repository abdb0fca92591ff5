"""Parts of built worlds (``streets``, ``long_corridors``): axis-aligned boxes and upright
prisms as closed solids, flat quads, and textures made in memory from the shipped ones.

A textured :class:`~homing_gym.scenes.mesh_part.MeshPart` shows its texture alone, which
repeats outside ``[0, 1]`` uv: the boxes here take uvs in metres divided by a tile size
(``u`` along each side, continuous across boxes that share a face line, ``v`` up), so a
brick or a window keeps its size on a wall of any length. Units: metres, z up.
"""

from __future__ import annotations

from functools import lru_cache

import cv2
import numpy as np
import trimesh

from homing_gym.scenes.mesh_part import MeshPart
from homing_gym.scenes.textures import load_texture

Mesh = tuple[np.ndarray, np.ndarray]
#: Corners (x, y) of each side of a unit box seen from outside, bottom left then bottom
#: right, and the sign and axis of ``u`` along it (left to right).
_SIDES = (((0, 0), (1, 0), +1, 0),     # -y side, u = x
          ((1, 0), (1, 1), +1, 1),     # +x side, u = y
          ((1, 1), (0, 1), -1, 0),     # +y side, u = -x
          ((0, 1), (0, 0), -1, 1))     # -x side, u = -y


def box_mesh(lo, hi, tile: tuple[float, float] = (1.0, 1.0)) -> tuple[np.ndarray, np.ndarray,
                                                                         np.ndarray]:
    """A closed box from corner ``lo`` to ``hi`` (x, y, z metres), wound outwards: its
    24 vertices (four per side), 12 faces and uvs (``u`` = the world coordinate along
    each side / ``tile[0]``, ``v`` = z / ``tile[1]``; top and bottom: x and y /
    ``tile[0]``)."""
    (x0, y0, z0), (x1, y1, z1) = lo, hi
    xs, ys = (x0, x1), (y0, y1)
    tu, tv = tile
    vertices, uvs = [], []
    for (ax, ay), (bx, by), sign, axis in _SIDES:
        a, b = (xs[ax], ys[ay]), (xs[bx], ys[by])
        for (x, y), z in ((a, z0), (b, z0), (b, z1), (a, z1)):
            vertices.append((x, y, z))
            uvs.append((sign * (x, y)[axis] / tu, z / tv))
    for z, corners in ((z1, ((x0, y0), (x1, y0), (x1, y1), (x0, y1))),
                       (z0, ((x0, y0), (x0, y1), (x1, y1), (x1, y0)))):
        for x, y in corners:
            vertices.append((x, y, z))
            uvs.append((x / tu, y / tu))
    quads = np.arange(24).reshape(6, 4)
    faces = np.concatenate([quads[:, [0, 1, 2]], quads[:, [0, 2, 3]]])
    return np.array(vertices, np.float64), faces, np.array(uvs, np.float64)


@lru_cache(maxsize=8)
def _unit_prism(sections: int) -> Mesh:
    """Vertices and faces of trimesh's cylinder of ``sections`` sides, radius 1 and
    height 1 about the origin (made once per number of sides)."""
    prism = trimesh.creation.cylinder(radius=1.0, height=1.0, sections=sections)
    vertices, faces = np.array(prism.vertices), np.array(prism.faces)
    vertices.flags.writeable = faces.flags.writeable = False
    return vertices, faces


def prism_mesh(xy, radius: float, z0: float, z1: float, sections: int = 10) -> Mesh:
    """A closed upright prism of ``sections`` sides (an approximate cylinder of
    ``radius``) from height ``z0`` to ``z1`` over floor point ``xy`` (metres)."""
    unit, faces = _unit_prism(sections)
    return unit * [radius, radius, z1 - z0] + [xy[0], xy[1], (z0 + z1) / 2], faces


def solids_part(meshes: list, colors: list, name: str, collision: bool,
                texture: np.ndarray | None = None) -> MeshPart:
    """One part of closed solids (each mesh ``(vertices, faces)`` or, with ``texture``,
    ``(vertices, faces, uvs)``; wound outwards), each solid in its colour (``colors``:
    one RGB per mesh; a textured part's colours are for TinyRenderer, the ray caster
    shows the texture)."""
    counts = [len(m[1]) for m in meshes]
    offsets = np.cumsum([0] + [len(m[0]) for m in meshes[:-1]])
    vertices = np.concatenate([m[0] for m in meshes])
    faces = np.concatenate([m[1] + o for m, o in zip(meshes, offsets)])
    face_colors = np.concatenate([np.broadcast_to(c, (n, 3)) for n, c in zip(counts, colors)])
    ends = np.cumsum(counts)
    solids = tuple(np.arange(end - n, end) for n, end in zip(counts, ends))
    uvs = None if texture is None else np.concatenate([m[2] for m in meshes])
    return MeshPart(vertices, faces, np.clip(face_colors, 0, 1), uvs=uvs, texture=texture,
                    collision=collision, name=name, solid_faces=solids)


def quads_part(quads, name: str, colors=None, texture: np.ndarray | None = None,
               uvs=None) -> MeshPart:
    """An open surface of flat quads (``(Q, 4, 3)`` corners in order round each),
    never blocking: with ``colors`` (one RGB per quad) or ``texture`` and ``uvs``
    (``(Q, 4, 2)``)."""
    quads = np.asarray(quads, np.float64).reshape(-1, 4, 3)
    n = len(quads)
    base = 4 * np.arange(n)[:, None]
    faces = np.concatenate([base + [0, 1, 2], base + [0, 2, 3]])
    if texture is not None:
        colors = np.broadcast_to(texture.reshape(-1, 3).mean(axis=0) / 255, (n, 3))
    colors = np.asarray(colors, np.float64).reshape(n, 3)
    return MeshPart(quads.reshape(-1, 3), faces, np.clip(np.concatenate([colors, colors]), 0, 1),
                    uvs=None if texture is None else np.asarray(uvs, np.float64).reshape(-1, 2),
                    texture=texture, collision=False, name=name, solid_faces=())


def floor_quad(x0: float, y0: float, x1: float, y1: float, z: float) -> np.ndarray:
    """The corners ``(4, 3)`` of a level rectangle at height ``z`` (metres), facing up."""
    return np.array([(x0, y0, z), (x1, y0, z), (x1, y1, z), (x0, y1, z)], np.float64)


def texture_color(texture: np.ndarray) -> np.ndarray:
    """The mean RGB (0-1) of a uint8 texture: the face colour TinyRenderer shows."""
    return texture.reshape(-1, 3).mean(axis=0) / 255


def tinted(name: str, rgb, contrast: float = 1.0) -> np.ndarray:
    """The shipped texture ``name`` (uint8 RGB) multiplied by ``rgb`` (0-1, relative to
    the texture's mean grey) with its contrast about the mean scaled by ``contrast``."""
    image = load_texture(name).astype(np.float64)
    mean = image.mean()
    image = mean + contrast * (image - mean)
    return np.clip(image / mean * 255 * np.asarray(rgb, np.float64), 0, 255).astype(np.uint8)


def scaled(image: np.ndarray, repeats: tuple[float, float], shape: tuple[int, int]) -> np.ndarray:
    """A texture of ``shape`` = (rows, columns) pixels showing ``image`` ``repeats`` =
    (across, down) times: ``image`` shrunk to one repeat's size (at least a pixel), then
    tiled and cut."""
    across, down = repeats
    rows, cols = shape
    small = cv2.resize(image, (max(1, round(cols / across)), max(1, round(rows / down))),
                       interpolation=cv2.INTER_AREA).reshape(max(1, round(rows / down)),
                                                              max(1, round(cols / across)), 3)
    tiles = np.tile(small, (-(-rows // small.shape[0]), -(-cols // small.shape[1]), 1))
    return np.ascontiguousarray(tiles[:rows, :cols])
