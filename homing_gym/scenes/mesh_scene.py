"""Worlds from triangle meshes: :class:`MeshScene` from a file (OBJ, PLY, GLB/glTF, STL,
anything ``trimesh.load`` reads) or from plain arrays, and the scene string
``"mesh:PATH"`` that every env and command accepts in place of a scene name.

The robot drives on the plane z = 0 of the (scaled, turned, shifted) mesh. Mesh triangles
that reach into the scene's height band block it (:mod:`homing_gym.scenes.footprint`);
the band's default, 0.02-0.35 m, leaves a mesh's own ground and anything above the robot
(ceilings, table tops) passable. Colours come from the file: per-face or per-vertex
colours, or a material's texture (the ray caster samples the texture through the UVs;
TinyRenderer, which takes one colour per PyBullet mesh, shows each face in the texture's
colour at its corners). Without ``bounds``, the free area is the footprint of the parts
that block the robot (of all parts if none do); ``fence`` (default on) keeps the robot
inside it even where the mesh has no walls.

``"mesh:PATH"`` takes options after ``?`` as ``key=value`` pairs joined by ``&``:
``scale`` (float), ``up`` (``z`` or ``y``), ``offset`` (``x,y,z`` metres), ``fence`` and
``ground_plane`` (``0``/``1``), ``bounds`` (``xmin,ymin,xmax,ymax`` metres), e.g.
``"mesh:/data/room.glb?up=y&scale=0.01"``.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from functools import lru_cache
from urllib.parse import parse_qsl

import numpy as np

from homing_gym.scenes.base import HEIGHT_BAND, Color, Scene
from homing_gym.scenes.footprint import band_triangles
from homing_gym.scenes.mesh_part import MeshPart
from homing_gym.validation import is_real

UP_AXES = ("z", "y")
#: Default colour (RGB) of faces a file gives no colour.
DEFAULT_FACE_COLOR = (0.7, 0.7, 0.7)
#: Margin (metres) around the blocking footprint when ``bounds`` are not given.
BOUNDS_MARGIN = 0.05


def _flag(value: str) -> bool:
    if value not in ("0", "1", "true", "false"):
        raise ValueError(f"expected 0, 1, true or false, got {value!r}")
    return value in ("1", "true")


def _bounds_from_list(values: list[float]):
    if len(values) != 4:
        raise ValueError(f"expected xmin,ymin,xmax,ymax, got {values!r}")
    return (values[0], values[1]), (values[2], values[3])


#: ``"mesh:PATH?key=value"`` options and how to read their values.
SPEC_OPTIONS = {
    "scale": float,
    "up": str,
    "offset": lambda v: tuple(float(x) for x in v.split(",")),
    "fence": _flag,
    "ground_plane": _flag,
    "bounds": lambda v: _bounds_from_list([float(x) for x in v.split(",")]),
}


def _placement(scale: float, up: str, offset) -> np.ndarray:
    """4 x 4 transform: scale, then turn ``up`` onto +z, then shift by ``offset``."""
    if not (is_real(scale) and scale > 0):
        raise ValueError(f"scale must be a positive number, got {scale!r}")
    if up not in UP_AXES:
        raise ValueError(f"unknown up axis {up!r}; allowed: {UP_AXES}")
    offset = tuple(offset)
    if len(offset) != 3 or not all(math.isfinite(float(v)) for v in offset):
        raise ValueError(f"offset must be three finite numbers (x, y, z metres), got {offset!r}")
    turn = np.eye(4)
    if up == "y":             # y up -> z up: (x, y, z) -> (x, -z, y)
        turn[:3, :3] = [[1, 0, 0], [0, 0, -1], [0, 1, 0]]
    place = np.diag([scale, scale, scale, 1.0])
    place = turn @ place
    place[:3, 3] = offset
    return place


def _transformed(part: MeshPart, transform: np.ndarray) -> MeshPart:
    vertices = part.vertices @ transform[:3, :3].T + transform[:3, 3]
    return MeshPart(vertices, part.faces, part.face_colors, part.uvs, part.texture,
                    part.collision, part.name)


@dataclass(frozen=True)
class MeshScene(Scene):
    """A :class:`~homing_gym.scenes.base.Scene` made from triangle meshes; build one with
    :meth:`from_file` or :meth:`from_arrays`."""

    @classmethod
    def from_parts(cls, parts: list[MeshPart], *, name: str = "mesh", scale: float = 1.0,
                   up: str = "z", offset=(0.0, 0.0, 0.0), bounds=None, fence: bool = True,
                   ground_plane: bool = True,
                   ground_color: Color = (0.55, 0.55, 0.55, 1.0),
                   sky_color: tuple[float, float, float] | None = None,
                   height_band: tuple[float, float] = HEIGHT_BAND) -> "MeshScene":
        """The scene of ``parts`` placed by ``scale`` (metres per mesh unit), ``up`` (the
        mesh's up axis, ``"z"`` or ``"y"``) and ``offset`` (metres, added last);
        ``bounds`` ((xmin, ymin), (xmax, ymax)) metres or the blocking footprint's box;
        other arguments as in :class:`~homing_gym.scenes.base.Scene`
        (``ground_color``: the floor's RGBA)."""
        if not parts:
            raise ValueError(f"mesh scene {name!r} has no mesh parts")
        transform = _placement(scale, up, offset)
        parts = tuple(_transformed(part, transform) for part in parts)
        if bounds is None:
            bounds = _footprint_bounds(parts, height_band, name)
        return cls(name=name, bounds=tuple(tuple(float(v) for v in b) for b in bounds),
                   meshes=parts, fence=fence, ground_plane=ground_plane,
                   floor_color=tuple(ground_color), sky_color=sky_color,
                   height_band=tuple(height_band))

    @classmethod
    def from_arrays(cls, vertices, faces, colors=None, *, collision: bool = True,
                    **options) -> "MeshScene":
        """One mesh of ``vertices`` ``(V, 3)`` and ``faces`` ``(F, 3)``; ``colors``: RGB
        in [0, 1] per face ``(F, 3)`` or per vertex ``(V, 3)`` (a face takes the mean of
        its corners; with as many vertices as faces, per face), or ``None`` (grey).
        Options as in :meth:`from_parts`."""
        vertices, faces = np.asarray(vertices, np.float64), np.asarray(faces)
        face_colors = np.tile(DEFAULT_FACE_COLOR, (len(faces), 1))
        if colors is not None:
            colors = np.asarray(colors, np.float64)
            per_vertex = colors.shape == (len(vertices), 3) and len(vertices) != len(faces)
            try:
                face_colors = colors[faces].mean(axis=1) if per_vertex else colors
            except IndexError:
                pass        # bad face indices: MeshPart names them
        part = MeshPart(vertices, faces, face_colors, collision=collision,
                        name=options.get("name", "mesh"))
        return cls.from_parts([part], **options)

    @classmethod
    def from_file(cls, path: str | os.PathLike, *, no_collision=(), collision: bool = True,
                  **options) -> "MeshScene":
        """The world in a mesh file (every geometry of a multi-part file, e.g. a glTF
        scene, becomes one :class:`MeshPart` named after its node). ``collision``: whether
        parts block the robot; ``no_collision``: names of parts it passes through
        (foliage, curtains). Options as in :meth:`from_parts`; ``name`` defaults to
        the file name. Raises ``ValueError`` naming the file when it is missing,
        unreadable, or holds no triangles."""
        parts = load_parts(path, collision=collision, no_collision=tuple(no_collision))
        options.setdefault("name", os.path.basename(os.fspath(path)))
        return cls.from_parts(parts, **options)


def load_parts(path, *, collision: bool = True,
               no_collision: tuple[str, ...] = ()) -> list[MeshPart]:
    """The :class:`MeshPart` of each geometry in the file at ``path`` (see
    :meth:`MeshScene.from_file`)."""
    import trimesh      # imported here: only mesh worlds need its loaders

    path = os.fspath(path)
    if not os.path.isfile(path):
        raise ValueError(f"mesh file {path!r} does not exist")
    try:
        loaded = trimesh.load(path, process=False)
    except Exception as error:   # trimesh raises many kinds for a broken file
        raise ValueError(f"cannot read mesh file {path!r}: {type(error).__name__}: {error}") \
            from None
    meshes = loaded.dump() if isinstance(loaded, trimesh.Scene) else [loaded]
    meshes = [m for m in meshes if isinstance(m, trimesh.Trimesh) and len(m.faces)]
    if not meshes:
        raise ValueError(f"mesh file {path!r} has no triangles (empty, or only points "
                         f"or lines)")
    names = [str(m.metadata.get("name") or m.metadata.get("node")
                 or os.path.basename(path)) for m in meshes]
    unknown = sorted(set(no_collision) - set(names))
    if unknown:
        raise ValueError(f"no_collision names {unknown} are not parts of {path!r}; its "
                         f"parts: {sorted(set(names))}")
    try:
        return [_part(m, name, collision and name not in no_collision)
                for m, name in zip(meshes, names)]
    except ValueError as error:
        raise ValueError(f"mesh file {path!r}: {error}") from None


def _part(mesh, name: str, collision: bool) -> MeshPart:
    """A trimesh mesh as a :class:`MeshPart`, with its colours or texture."""
    visual = mesh.visual
    uvs = texture = None
    if visual.kind == "texture":
        image = getattr(visual.material, "image", None) or getattr(
            visual.material, "baseColorTexture", None)
        if image is not None and visual.uv is not None and len(visual.uv) == len(mesh.vertices):
            uvs = np.asarray(visual.uv, np.float64)
            texture = np.asarray(image.convert("RGB"), np.uint8)
    if visual.kind is None:
        face_colors = np.tile(DEFAULT_FACE_COLOR, (len(mesh.faces), 1))
    else:
        from trimesh.visual.color import vertex_to_face_color

        rgba = (vertex_to_face_color(visual.to_color().vertex_colors, mesh.faces)
                if visual.kind == "texture" else visual.face_colors)
        face_colors = np.asarray(rgba, np.float64)[:, :3] / 255.0
    return MeshPart(np.asarray(mesh.vertices, np.float64), np.asarray(mesh.faces), face_colors,
                    uvs, texture, collision, name)


def _footprint_bounds(parts: tuple[MeshPart, ...], band, name: str):
    """The floor box of the parts' triangles in ``band`` that block the robot (of all
    parts' triangles in the band if none block), plus :data:`BOUNDS_MARGIN`."""
    blocking = [band_triangles(p, band) for p in parts if p.collision]
    points = [t[..., :2].reshape(-1, 2) for t in blocking if len(t)]
    if not points:
        points = [t[..., :2].reshape(-1, 2) for t in (band_triangles(p, band) for p in parts)
                  if len(t)]
    if not points:
        raise ValueError(
            f"mesh scene {name!r}: no triangle lies at the robot's height "
            f"({band[0]}-{band[1]} m above z = 0), so the free area is unknown; check "
            f"scale, up and offset, or give bounds")
    xy = np.concatenate(points)
    low, high = xy.min(axis=0) - BOUNDS_MARGIN, xy.max(axis=0) + BOUNDS_MARGIN
    return (float(low[0]), float(low[1])), (float(high[0]), float(high[1]))


def parse_mesh_spec(spec: str) -> tuple[str, dict]:
    """``"mesh:PATH?key=value&..."`` -> (path, options for :meth:`MeshScene.from_file`)."""
    body = spec[len("mesh:"):]
    path, _, query = body.partition("?")
    if not path:
        raise ValueError(f"scene {spec!r}: give a file after 'mesh:', e.g. 'mesh:world.obj'")
    options = {}
    for key, value in parse_qsl(query, keep_blank_values=True, strict_parsing=bool(query)):
        if key not in SPEC_OPTIONS:
            raise ValueError(f"scene {spec!r}: unknown option {key!r}; allowed: "
                             f"{sorted(SPEC_OPTIONS)}")
        try:
            options[key] = SPEC_OPTIONS[key](value)
        except ValueError as error:
            raise ValueError(f"scene {spec!r}: bad {key}={value!r}: {error}") from None
    return path, options


def mesh_scene_from_spec(spec: str) -> MeshScene:
    """The :class:`MeshScene` named by a ``"mesh:PATH?..."`` string; a file is read once
    per process while it is unchanged."""
    path, options = parse_mesh_spec(spec)
    if not os.path.isfile(path):
        raise ValueError(f"scene {spec!r}: mesh file {path!r} does not exist")
    stat = os.stat(path)
    return _cached_scene(os.path.abspath(path), stat.st_mtime_ns, stat.st_size,
                         tuple(sorted(options.items())))


@lru_cache(maxsize=8)
def _cached_scene(path: str, mtime: int, size: int, options: tuple) -> MeshScene:
    return MeshScene.from_file(path, **dict(options))
