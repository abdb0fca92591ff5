"""A scene as one set of textured triangles: what the ray-cast renderer sees.

:func:`world_mesh` turns a :class:`~homing_gym.scenes.base.Scene` into triangles: the top
face of its floor and the sides of its :mod:`~homing_gym.scenes.solids` (the description the
PyBullet bodies are built from too: boxes as boxes, cylinders as 64-sided prisms), then its
mesh parts as they are; a textured part's texture repeats outside ``[0, 1]`` uv. Each
triangle has a colour (RGB in ``[0, 1]``), a texture index (``-1``: none) and texture
coordinates per corner: ``u`` left to right, ``v`` bottom to top, each box side and the
floor covered by its texture once (a panel's front side only), a cylinder's side wrapped
once around. The texture colour is multiplied by the body colour, as PyBullet does. The
triangles of closed solids (boxes, prisms) are wound counter-clockwise seen from outside
and marked ``closed``, as are the faces of a mesh part's closed solids
(:attr:`~homing_gym.scenes.mesh_part.MeshPart.solids`): from outside a solid, its faces
turned away are hidden behind its other faces, so the renderer skips them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from homing_gym.scenes.base import Scene
from homing_gym.scenes.mesh_part import MeshPart
from homing_gym.scenes.solids import Solid, floor_rectangle, floor_top, landmark_solid, wall_solid
from homing_gym.scenes.textures import load_texture

#: Sides of the prism that stands for a cylinder: the silhouette is within
#: ``r (1 - cos(pi/64))`` = 0.1 % of the radius of the true circle.
CYLINDER_SIDES = 64


@dataclass
class WorldMesh:
    """``triangles`` ``(N, 3, 3)`` float32 corners (metres); ``colors`` ``(N, 3)``;
    ``texture`` ``(N,)`` index into ``textures`` or ``-1``; ``uvs`` ``(N, 3, 2)``;
    ``textures``: float32 RGB images in ``[0, 1]``, row 0 at the top; ``closed`` ``(N,)``
    bool: part of a closed solid, wound counter-clockwise seen from outside (then the
    normal points out)."""

    triangles: np.ndarray
    colors: np.ndarray
    texture: np.ndarray
    uvs: np.ndarray
    textures: list[np.ndarray]
    closed: np.ndarray

    @property
    def normals(self) -> np.ndarray:
        """Unit face normals ``(N, 3)`` (right-handed in corner order: outward on closed
        solids, arbitrary elsewhere; shading is two-sided)."""
        n = np.cross(self.triangles[:, 1] - self.triangles[:, 0],
                     self.triangles[:, 2] - self.triangles[:, 0])
        return n / np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-12)


class _Builder:
    """Collects quads and triangles with their materials."""

    def __init__(self) -> None:
        self.tris: list[np.ndarray] = []
        self.colors: list[np.ndarray] = []
        self.tex: list[int] = []
        self.uvs: list[np.ndarray] = []
        self.textures: list[np.ndarray] = []
        self.closed: list[bool] = []
        self.inside: list[np.ndarray] = []      # a point inside the solid, or NaN
        self._texture_ids: dict[str, int] = {}

    def texture_id(self, name: str | None) -> int:
        if name is None:
            return -1
        if name not in self._texture_ids:
            self._texture_ids[name] = self.add_texture(load_texture(name))
        return self._texture_ids[name]

    def add_texture(self, image: np.ndarray) -> int:
        """Index of a new texture (uint8 RGB, row 0 at the top)."""
        self.textures.append(image.astype(np.float32) / 255.0)
        return len(self.textures) - 1

    def triangle(self, corners, uv, color, tex: int, inside=None) -> None:
        """One triangle; ``inside``: a point inside the closed solid it bounds (the
        triangle is then wound counter-clockwise seen from outside, in :meth:`mesh`), or
        None."""
        self.tris.append(np.asarray(corners, np.float64))
        self.uvs.append(np.asarray(uv, np.float64))
        self.inside.append(np.full(3, np.nan) if inside is None
                           else np.asarray(inside, np.float64))
        self.colors.append(np.asarray(color[:3], np.float64))
        self.tex.append(tex)
        self.closed.append(inside is not None)

    def quad(self, corners, uv, color, tex: int, inside=None) -> None:
        """Corners in order around the quad; ``uv`` per corner; ``inside`` as in
        :meth:`triangle`."""
        c, t = np.asarray(corners, np.float64), np.asarray(uv, np.float64)
        for i, j, k in ((0, 1, 2), (0, 2, 3)):
            self.triangle(c[[i, j, k]], t[[i, j, k]], color, tex, inside)

    def solid(self, solid: Solid) -> None:
        """The sides of a box, panel or cylinder (textured as :class:`Solid` says)."""
        tex = self.texture_id(solid.texture)
        if solid.shape == "cylinder":
            self.cylinder(solid.centre, solid.radius, solid.height, solid.yaw, solid.color, tex)
        else:
            self.box(solid.centre, solid.half, solid.yaw, solid.color, tex,
                     front_only_uv=solid.shape == "panel")

    def box(self, centre, half, yaw: float, color, tex: int, front_only_uv: bool = False) -> None:
        """A box; every side textured once (``front_only_uv``: only the local +y side,
        the others take the texture's top-left texel, like a panel)."""
        hx, hy, hz = half
        rot = np.array([[math.cos(yaw), -math.sin(yaw), 0], [math.sin(yaw), math.cos(yaw), 0],
                        [0, 0, 1]])
        corner_uv = [(0.001, 0.999)] * 4

        def world(p):
            return np.asarray(centre) + rot @ np.asarray(p, np.float64)

        sides = {  # (corners bottom-left, bottom-right, top-right, top-left as seen from out)
            "+y": [(hx, hy, -hz), (-hx, hy, -hz), (-hx, hy, hz), (hx, hy, hz)],
            "-y": [(-hx, -hy, -hz), (hx, -hy, -hz), (hx, -hy, hz), (-hx, -hy, hz)],
            "+x": [(hx, -hy, -hz), (hx, hy, -hz), (hx, hy, hz), (hx, -hy, hz)],
            "-x": [(-hx, hy, -hz), (-hx, -hy, -hz), (-hx, -hy, hz), (-hx, hy, hz)],
            "+z": [(-hx, -hy, hz), (hx, -hy, hz), (hx, hy, hz), (-hx, hy, hz)],
            "-z": [(-hx, hy, -hz), (hx, hy, -hz), (hx, -hy, -hz), (-hx, -hy, -hz)],
        }
        full = [(0, 0), (1, 0), (1, 1), (0, 1)]
        for name, corners in sides.items():
            uv = full if (not front_only_uv or name == "+y") else corner_uv
            self.quad([world(p) for p in corners], uv, color, tex, inside=centre)

    def cylinder(self, centre, radius: float, height: float, yaw: float, color,
                 tex: int) -> None:
        """A closed prism of :data:`CYLINDER_SIDES` sides: per side, its quad's two
        triangles, then the bottom and top triangles fanning from the axis."""
        a = yaw + np.linspace(0, 2 * math.pi, CYLINDER_SIDES + 1)
        x, y = centre[0] + radius * np.cos(a), centre[1] + radius * np.sin(a)
        z0, z1 = centre[2] - height / 2, centre[2] + height / 2
        u = np.linspace(0, 1, CYLINDER_SIDES + 1)
        n = CYLINDER_SIDES
        now, nxt = np.arange(n), np.arange(1, n + 1)

        def rim(z: float, k: np.ndarray) -> np.ndarray:
            return np.column_stack([x[k], y[k], np.full(n, z)])

        def axis(z: float) -> np.ndarray:
            return np.broadcast_to([centre[0], centre[1], z], (n, 3))

        quad = np.stack([rim(z0, now), rim(z0, nxt), rim(z1, nxt), rim(z1, now)], 1)
        quad_uv = np.stack([np.column_stack([u[now], np.zeros(n)]),
                            np.column_stack([u[nxt], np.zeros(n)]),
                            np.column_stack([u[nxt], np.ones(n)]),
                            np.column_stack([u[now], np.ones(n)])], 1)
        caps = [np.stack([axis(z), rim(z, now), rim(z, nxt)], 1) for z in (z0, z1)]
        tris = np.stack([quad[:, [0, 1, 2]], quad[:, [0, 2, 3]], *caps], 1).reshape(-1, 3, 3)
        cap_uv = np.full((n, 3, 2), 0.001)
        uvs = np.stack([quad_uv[:, [0, 1, 2]], quad_uv[:, [0, 2, 3]], cap_uv, cap_uv],
                       1).reshape(-1, 3, 2)
        self.tris.extend(tris)
        self.uvs.extend(uvs)
        self.inside.extend(np.broadcast_to(np.asarray(centre, np.float64), (len(tris), 3)))
        self.colors.extend(np.broadcast_to(np.asarray(color[:3], np.float64), (len(tris), 3)))
        self.tex.extend([tex] * len(tris))
        self.closed.extend([True] * len(tris))

    def part(self, part: MeshPart) -> None:
        """A mesh part's faces (those of its closed solids marked ``closed``); a textured
        part shows its texture alone (its face colours are the texture's, for
        TinyRenderer)."""
        tris = part.triangles
        self.tris.extend(tris)
        self.closed.extend(part.closed)
        self.inside.extend(np.full((len(tris), 3), np.nan))
        if part.texture is None:
            self.colors.extend(part.face_colors)
            self.tex.extend([-1] * len(tris))
            self.uvs.extend(np.full((len(tris), 3, 2), 0.001))
        else:
            self.colors.extend(np.ones((len(tris), 3)))
            self.tex.extend([self.add_texture(part.texture)] * len(tris))
            self.uvs.extend(part.uvs[part.faces])

    def mesh(self) -> WorldMesh:
        """The collected triangles; those of built solids turned counter-clockwise seen
        from outside (their normal pointing away from the point inside)."""
        tris, uvs = np.array(self.tris, np.float64), np.array(self.uvs, np.float64)
        inside = np.array(self.inside, np.float64).reshape(-1, 3)
        normal = np.cross(tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0])
        outward = np.einsum("ij,ij->i", normal, tris.mean(axis=1) - inside)
        flip = outward < 0                              # False where inside is NaN
        tris[flip], uvs[flip] = tris[flip][:, [0, 2, 1]], uvs[flip][:, [0, 2, 1]]
        return WorldMesh(tris.astype(np.float32), np.array(self.colors, np.float32),
                         np.array(self.tex, np.int32), uvs.astype(np.float32),
                         self.textures, np.array(self.closed, bool))


def world_mesh(scene: Scene) -> WorldMesh:
    """The triangles of ``scene``'s floor (if ``ground_plane``), walls, landmarks and mesh
    parts (see the module doc)."""
    b = _Builder()
    if scene.ground_plane:
        x0, y0, x1, y1 = floor_rectangle(scene)
        z = floor_top(scene)
        b.quad([(x0, y0, z), (x1, y0, z), (x1, y1, z), (x0, y1, z)],
               [(0, 0), (1, 0), (1, 1), (0, 1)], scene.floor_color,
               b.texture_id(scene.floor_texture))
    for solid in [*map(wall_solid, scene.walls), *map(landmark_solid, scene.landmarks)]:
        b.solid(solid)
    for part in scene.meshes:
        b.part(part)
    return b.mesh()
