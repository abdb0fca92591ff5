"""Triangle meshes in a scene: :class:`MeshPart`, plain arrays in world coordinates.

A part is what a user's mesh file (or a procedural generator) adds to a
:class:`~homing_gym.scenes.base.Scene` beside its walls and landmarks. Units: metres,
z up, the floor at z = 0. Both renderers draw it (the ray caster with its texture, if it
has one; TinyRenderer with its face colours) and, with ``collision``, the robot bumps
into its triangles that reach into the scene's height band
(:mod:`homing_gym.scenes.footprint`).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np


#: The most triangles the meshes of one world may hold together. Measured (2026-11-28,
#: 2 cores): a 20 m terrain grid of 1,000,000 triangles took 25 s to become an env and
#: 1.8 GB at its peak, one of 2,000,000 took 49 s and 3.4 GB (the clearance field, the
#: ray caster's mesh and PyBullet's trees of the blocking ones, in shapes of at most
#: 43,690 triangles each).
MAX_WORLD_FACES = 2_000_000


def check_face_count(count: int, owner: str) -> None:
    """``ValueError`` naming ``owner`` (e.g. "mesh file 'x.ply'"), ``count`` and the
    limit when ``count`` triangles are more than :data:`MAX_WORLD_FACES`."""
    if count > MAX_WORLD_FACES:
        raise ValueError(f"{owner} has {count:,} triangles, more than the {MAX_WORLD_FACES:,} "
                         f"a world may hold (loading takes about 25 s and 1.8 GB a million); "
                         f"simplify the mesh, e.g. with a decimation tool")


@dataclass(frozen=True, eq=False)
class MeshPart:
    """``vertices`` ``(V, 3)`` (metres), ``faces`` ``(F, 3)`` vertex indices,
    ``face_colors`` ``(F, 3)`` RGB in ``[0, 1]``; optionally ``uvs`` ``(V, 2)`` (u left
    to right, v bottom to top) and ``texture`` (uint8 ``(H, W, 3)``, row 0 at the top),
    which the ray caster uses instead of the face colours. ``collision``: the robot
    bumps into it. ``solid_faces``: the face indices of each closed solid wound outwards,
    where the part's maker knows them (a generator that built them so); ``None``: found
    with trimesh (:attr:`solids`). Parts compare by identity (their arrays are not
    hashed)."""

    vertices: np.ndarray
    faces: np.ndarray
    face_colors: np.ndarray
    uvs: np.ndarray | None = None
    texture: np.ndarray | None = None
    collision: bool = True
    name: str = "mesh"
    solid_faces: tuple[np.ndarray, ...] | None = None

    def __post_init__(self) -> None:
        owner = f"mesh part {self.name!r}"
        vertices = np.asarray(self.vertices, np.float64)
        faces = np.asarray(self.faces)
        if vertices.ndim != 2 or vertices.shape[1] != 3 or len(vertices) == 0:
            raise ValueError(f"{owner}: vertices must be a non-empty (V, 3) array, "
                             f"got shape {vertices.shape}")
        if not np.all(np.isfinite(vertices)):
            raise ValueError(f"{owner}: vertices contain NaN or infinity "
                             f"({int(np.sum(~np.isfinite(vertices)))} values)")
        if faces.ndim != 2 or faces.shape[1] != 3 or len(faces) == 0:
            raise ValueError(f"{owner}: has no faces (faces must be a non-empty (F, 3) "
                             f"array of vertex indices, got shape {faces.shape})")
        if faces.dtype.kind not in "iu" or faces.min() < 0 or faces.max() >= len(vertices):
            raise ValueError(f"{owner}: face indices must be integers in "
                             f"[0, {len(vertices) - 1}]")
        colors = np.asarray(self.face_colors, np.float64)
        if colors.shape != (len(faces), 3) or not np.all((colors >= 0) & (colors <= 1)):
            raise ValueError(f"{owner}: face_colors must be ({len(faces)}, 3) RGB values "
                             f"in [0, 1], got shape {colors.shape}")
        if (self.uvs is None) != (self.texture is None):
            raise ValueError(f"{owner}: give both uvs and texture, or neither")
        if self.texture is not None:
            uvs, texture = np.asarray(self.uvs, np.float64), np.asarray(self.texture)
            if uvs.shape != (len(vertices), 2) or not np.all(np.isfinite(uvs)):
                raise ValueError(f"{owner}: uvs must be finite ({len(vertices)}, 2), "
                                 f"got shape {uvs.shape}")
            if (texture.ndim != 3 or texture.shape[2] != 3 or texture.dtype != np.uint8
                    or texture.size == 0):
                raise ValueError(f"{owner}: texture must be uint8 (H, W, 3) with H, W >= 1, got "
                                 f"{texture.dtype} {texture.shape}")
            object.__setattr__(self, "uvs", uvs)
            object.__setattr__(self, "texture", texture)
        if self.solid_faces is not None:
            solids = tuple(np.sort(np.asarray(f, np.int64)) for f in self.solid_faces)
            if any(f.ndim != 1 or len(f) == 0 or f[0] < 0 or f[-1] >= len(faces)
                   for f in solids):
                raise ValueError(f"{owner}: solid_faces must be non-empty lists of face "
                                 f"indices in [0, {len(faces) - 1}]")
            object.__setattr__(self, "solid_faces", solids)
        object.__setattr__(self, "vertices", vertices)
        object.__setattr__(self, "faces", faces.astype(np.int64))
        object.__setattr__(self, "face_colors", colors)

    @property
    def triangles(self) -> np.ndarray:
        """Corners ``(F, 3, 3)`` of every face (metres)."""
        return self.vertices[self.faces]

    @cached_property
    def solids(self) -> list[np.ndarray]:
        """Face indices of each closed solid in the part: a connected component that is
        watertight and wound outwards (``trimesh`` ``is_volume``; a room's inward-wound
        shell and open surfaces are not). Computed once per part, unless the part's
        maker gave them (``solid_faces``)."""
        if self.solid_faces is not None:
            return list(self.solid_faces)
        import trimesh     # only mesh worlds need it

        mesh = trimesh.Trimesh(self.vertices, self.faces, process=False)
        mesh.merge_vertices()                  # files often repeat corners per face
        components = trimesh.graph.connected_components(
            mesh.face_adjacency, nodes=np.arange(len(self.faces)), min_len=4)
        return [np.sort(faces) for faces in components
                if mesh.submesh([faces], append=True).is_volume]

    @property
    def closed(self) -> np.ndarray:
        """``(F,)`` bool: the face belongs to one of :attr:`solids` (then its normal, in
        corner order, points out of the solid)."""
        mask = np.zeros(len(self.faces), bool)
        for faces in self.solids:
            mask[faces] = True
        return mask
