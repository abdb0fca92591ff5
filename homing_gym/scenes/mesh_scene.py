"""Worlds from triangle meshes: :class:`MeshScene` from a file (OBJ, PLY, GLB/glTF, STL,
anything ``trimesh.load`` reads) or from plain arrays, and the scene string
``"mesh:PATH?key=value&key=value"`` that every env and command accepts in place of a
scene name.

The robot drives on the plane z = 0 of the (scaled, turned, shifted) mesh. Mesh triangles
that reach into the scene's height band block it (:mod:`homing_gym.scenes.footprint`);
the band's default, 0.02-0.35 m, leaves a mesh's own ground and anything above the robot
(ceilings, table tops) passable. Without ``bounds``, the free area is the footprint of the
parts that block the robot (of all parts if none do); ``fence`` (default on) keeps the
robot inside it even where the mesh has no walls.

Colours come from the file: per-face or per-vertex colours, or each part's material: its
texture through the UVs (the ray caster samples it; TinyRenderer, which takes one colour
per PyBullet mesh, shows each face in the texture's colour at its corners), else its main
colour (glTF ``baseColorFactor``, OBJ ``Kd``), times the vertex colours where a glTF has
both. A texture without UVs shows as its mean colour. Alpha is ignored (all opaque).

The options (:class:`MeshOptions`), as keywords of :meth:`MeshScene.from_file` or after
``?`` in the scene string, taken literally (lists comma-separated); each once:

==============  ========================  ====================  ==============================
option          scene-string value        default               meaning
==============  ========================  ====================  ==============================
scale           ``0.0254``                1                     metres per mesh unit
up              ``z`` or ``y``            z                     the mesh's up axis (to +z)
offset          ``x,y,z``                 0,0,0                 metres, added last
bounds          ``xmin,ymin,xmax,ymax``   blocking footprint    free floor (m), <= 100 m a side
fence           ``0`` or ``1``            1                     invisible walls on the bounds
ground_plane    ``0`` or ``1``            1                     a floor 2 mm below z = 0
ground_color    ``r,g,b`` or ``r,g,b,a``  0.55,0.55,0.55,1      its colour, in [0, 1]
sky_color       ``r,g,b``                 the env's             ray caster background, [0, 1]
height_band     ``low,high``              0.02,0.35             metres in which faces block
collision       ``0`` or ``1``            1                     ``0``: nothing blocks
no_collision    ``name,name``             none                  parts the robot passes through
==============  ========================  ====================  ==============================

e.g. ``"mesh:/data/office.glb?scale=0.0254&bounds=-10,-8,10,8&no_collision=curtain"``.
"""

from __future__ import annotations

import difflib
import os
from collections.abc import Callable, Mapping
from dataclasses import dataclass, fields, replace
from functools import lru_cache

import numpy as np

from homing_gym.scenes.base import HEIGHT_BAND, MAX_COORDINATE, Color, Scene
from homing_gym.scenes.footprint import band_triangles
from homing_gym.scenes.mesh_part import MeshPart, check_face_count
from homing_gym.validation import is_real, require_positive

UP_AXES = ("z", "y")
#: Default colour (RGB) of faces a file gives no colour.
DEFAULT_FACE_COLOR = (0.7, 0.7, 0.7)
#: Margin (metres) around the blocking footprint when ``bounds`` are not given.
BOUNDS_MARGIN = 0.05


def _reals(value, *shapes: tuple[int, ...]) -> list | None:
    """``value`` as (nested) lists of floats if it has one of ``shapes`` and holds only
    finite real numbers (no strings or bools), else ``None``."""
    try:
        items = np.array(value, dtype=object)
    except ValueError:          # ragged nesting
        return None
    if items.shape not in shapes or not all(is_real(v) for v in items.flat):
        return None
    return items.astype(np.float64).tolist()


@dataclass(frozen=True)
class MeshOptions:
    """How a mesh becomes a world (the table in :mod:`homing_gym.scenes.mesh_scene`):
    ``scale`` metres per mesh unit, ``up`` axis, ``offset`` (x, y, z) metres, ``bounds``
    ((xmin, ymin), (xmax, ymax)) metres or ``None`` (the blocking footprint), ``fence``,
    ``ground_plane``, ``ground_color`` RGB(A) and ``sky_color`` RGB in [0, 1],
    ``height_band`` (low, high) metres, ``collision``, ``no_collision`` part names.
    Checked when made: each bad value is a ``ValueError`` naming the option."""

    scale: float = 1.0
    up: str = "z"
    offset: tuple[float, float, float] = (0.0, 0.0, 0.0)
    bounds: tuple[tuple[float, float], tuple[float, float]] | None = None
    fence: bool = True
    ground_plane: bool = True
    ground_color: Color = (0.55, 0.55, 0.55, 1.0)
    sky_color: tuple[float, float, float] | None = None
    height_band: tuple[float, float] = HEIGHT_BAND
    collision: bool = True
    no_collision: tuple[str, ...] = ()

    @classmethod
    def of(cls, options: Mapping) -> "MeshOptions":
        """The options named in ``options``; an unknown name is a ``ValueError`` that
        lists the allowed ones (and the closest, if it looks misspelt)."""
        for key in options:
            _check_option_name(key)
        return cls(**options)

    def __post_init__(self) -> None:
        def bad(name: str, allowed: str) -> ValueError:
            return ValueError(f"{name} must be {allowed}, got {getattr(self, name)!r}")

        def put(name: str, value) -> None:
            object.__setattr__(self, name, value)

        put("scale", require_positive("scale", self.scale, "metres per mesh unit"))
        if self.up not in UP_AXES:
            raise bad("up", f"the mesh's up axis, one of {UP_AXES}")
        offset = _reals(self.offset, (3,))
        if offset is None:
            raise bad("offset", "three finite numbers x, y, z (metres)")
        put("offset", tuple(offset))
        if self.bounds is not None:
            box = _reals(self.bounds, (2, 2))
            if box is None or not (box[0][0] < box[1][0] and box[0][1] < box[1][1]):
                raise bad("bounds", "((xmin, ymin), (xmax, ymax)) finite metres with "
                                    "xmin < xmax and ymin < ymax")
            put("bounds", tuple(map(tuple, box)))
        for name in ("fence", "ground_plane", "collision"):
            if not isinstance(getattr(self, name), (bool, np.bool_)):
                raise bad(name, "True or False (0 or 1 in a scene string)")
            put(name, bool(getattr(self, name)))
        ground = _reals(self.ground_color, (3,), (4,))
        if ground is None or not all(0 <= v <= 1 for v in ground):
            raise bad("ground_color", "3 or 4 numbers (RGB or RGBA) in [0, 1]")
        put("ground_color", (*ground, 1.0)[:4])
        if self.sky_color is not None:
            sky = _reals(self.sky_color, (3,))
            if sky is None or not all(0 <= v <= 1 for v in sky):
                raise bad("sky_color", "3 numbers (RGB) in [0, 1], or None")
            put("sky_color", tuple(sky))
        band = _reals(self.height_band, (2,))
        if band is None or not 0 <= band[0] < band[1]:
            raise bad("height_band", "(low, high) finite metres with 0 <= low < high")
        put("height_band", tuple(band))
        names = self.no_collision
        if not (isinstance(names, (list, tuple))
                and all(isinstance(n, str) and n for n in names)):
            raise bad("no_collision", "a list or tuple of part names (non-empty strings)")
        put("no_collision", tuple(names))


def _check_option_name(key: str) -> None:
    allowed = [f.name for f in fields(MeshOptions)]
    if key not in allowed:
        close = difflib.get_close_matches(str(key), allowed, n=1)
        hint = f" (did you mean {close[0]!r}?)" if close else ""
        raise ValueError(f"unknown option {key!r}{hint}; allowed: {', '.join(allowed)}")


def _placement(options: MeshOptions) -> np.ndarray:
    """4 x 4 transform: scale, then turn ``up`` onto +z, then shift by ``offset``."""
    place = np.diag([options.scale] * 3 + [1.0])
    if options.up == "y":             # y up -> z up: (x, y, z) -> (x, -z, y)
        place[:3, :3] = np.array([[1, 0, 0], [0, 0, -1], [0, 1, 0]]) @ place[:3, :3]
    place[:3, 3] = options.offset
    return place


@dataclass(frozen=True)
class MeshScene(Scene):
    """A :class:`~homing_gym.scenes.base.Scene` made from triangle meshes; build one with
    :meth:`from_file`, :meth:`from_arrays` or :meth:`from_parts`."""

    @classmethod
    def from_parts(cls, parts: list[MeshPart], *, name: str = "mesh",
                   **options) -> "MeshScene":
        """The scene of ``parts`` placed and set up by ``options`` (the fields of
        :class:`MeshOptions`; a part that does not collide stays so)."""
        return cls._build(parts, name, MeshOptions.of(options))

    @classmethod
    def from_arrays(cls, vertices, faces, colors=None, *, name: str = "mesh",
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
        part = MeshPart(vertices, faces, face_colors, name=name)
        return cls.from_parts([part], name=name, **options)

    @classmethod
    def from_file(cls, path: str | os.PathLike, *, name: str | None = None,
                  **options) -> "MeshScene":
        """The world in a mesh file (every geometry of a multi-part file, e.g. a glTF
        scene or an OBJ with several materials, becomes one :class:`MeshPart` named
        after its node or material). ``name`` defaults to the file name; ``options`` as
        in :meth:`from_parts`, checked before the file is read. Raises ``ValueError``
        naming the file when it is missing, a directory, unreadable, or holds no
        triangles, and naming the part when its colours do not fit its vertices."""
        checked = MeshOptions.of(options)
        return cls._build(load_parts(path), name or os.path.basename(os.fspath(path)),
                          checked)

    @classmethod
    def _build(cls, parts: list[MeshPart], name: str, options: MeshOptions) -> "MeshScene":
        if not parts:
            raise ValueError(f"mesh scene {name!r} has no mesh parts")
        check_face_count(sum(len(p.faces) for p in parts), f"mesh scene {name!r}")
        unknown = sorted(set(options.no_collision) - {p.name for p in parts})
        if unknown:
            raise ValueError(f"no_collision names {unknown} are not parts of {name!r}; its "
                             f"parts: {sorted({p.name for p in parts})}")
        transform = _placement(options)
        parts = tuple(replace(
            part, vertices=part.vertices @ transform[:3, :3].T + transform[:3, 3],
            collision=(part.collision and options.collision
                       and part.name not in options.no_collision)) for part in parts)
        _check_placed_extent(parts, name)
        bounds = options.bounds or _footprint_bounds(parts, options.height_band, name)
        return cls(name=name, bounds=bounds, meshes=parts, fence=options.fence,
                   ground_plane=options.ground_plane, floor_color=options.ground_color,
                   sky_color=options.sky_color, height_band=options.height_band)


def _check_placed_extent(parts: tuple[MeshPart, ...], name: str) -> None:
    """``ValueError`` if a placed vertex lies farther than :data:`MAX_COORDINATE` metres
    from the origin along any axis (far from the origin the renderers' 32-bit floats
    blur the world into sky: check ``scale`` and ``offset``)."""
    reach = max(float(np.max(np.abs(p.vertices))) for p in parts)
    if not reach <= MAX_COORDINATE:
        raise ValueError(f"mesh scene {name!r}: placed by scale and offset, it reaches "
                         f"{reach:.3g} m from the origin; every vertex must lie within "
                         f"{MAX_COORDINATE:g} m of it along each axis: check scale and "
                         f"offset")


def _mesh_file(path: str) -> None:
    """``ValueError`` unless ``path`` is a file."""
    if os.path.isdir(path):
        raise ValueError(f"mesh file {path!r} is a directory, not a mesh file")
    if not os.path.isfile(path):
        raise ValueError(f"mesh file {path!r} does not exist")


def load_parts(path: str | os.PathLike) -> list[MeshPart]:
    """The :class:`MeshPart` of each geometry in the file at ``path``, all colliding (see
    :meth:`MeshScene.from_file`)."""
    import trimesh      # imported here: only mesh worlds need its loaders

    path = os.fspath(path)
    _mesh_file(path)
    try:
        loaded = trimesh.load(path, process=False)
    except Exception as error:   # trimesh raises many kinds for a broken file
        raise ValueError(f"cannot read mesh file {path!r}: {type(error).__name__}: {error}") \
            from None
    meshes = loaded.dump() if isinstance(loaded, trimesh.Scene) else [loaded]
    meshes = [m for m in meshes if isinstance(m, trimesh.Trimesh) and len(m.faces)]
    if isinstance(loaded, trimesh.Scene):
        for mesh in meshes:     # dump's copies lose a glTF's vertex colours beside a
            source = loaded.geometry[mesh.metadata["name"]].visual   # material (trimesh#2153)
            if "color" in getattr(source, "vertex_attributes", {}):
                mesh.visual.vertex_attributes["color"] = source.vertex_attributes["color"]
    if not meshes:
        raise ValueError(f"mesh file {path!r} has no triangles (empty, or only points "
                         f"or lines)")
    check_face_count(sum(len(m.faces) for m in meshes), f"mesh file {path!r}")
    try:
        return [_part(m, str(m.metadata.get("name") or m.metadata.get("node")
                             or os.path.basename(path))) for m in meshes]
    except ValueError as error:
        raise ValueError(f"mesh file {path!r}: {error}") from None


def _part(mesh, name: str) -> MeshPart:
    """A trimesh mesh as a :class:`MeshPart`, with its colours or texture."""
    part = MeshPart(np.asarray(mesh.vertices, np.float64), np.asarray(mesh.faces),
                    np.tile(DEFAULT_FACE_COLOR, (len(mesh.faces), 1)), name=name)
    visual, count = mesh.visual, len(part.vertices)
    uvs = texture = None
    try:
        if visual.kind == "face":
            face_colors = _rgb(visual.face_colors, len(part.faces), "face")
        else:
            if visual.kind == "vertex":
                colors = _rgb(visual.vertex_colors, count, "vertex")
            elif visual.kind == "texture":
                colors, uvs, texture = _material_colors(visual, count)
            else:                   # no colours in the file
                return part
            face_colors = colors[part.faces].mean(axis=1)
    except ValueError as error:
        raise ValueError(f"mesh part {name!r}: {error}") from None
    return replace(part, face_colors=face_colors / 255, uvs=uvs, texture=texture)


def _rgb(colors, count: int, what: str) -> np.ndarray:
    """Colours as trimesh gives them (one, or one per item; RGB or RGBA; 0-255 or 0-1)
    as ``(count, 3)`` RGB in [0, 255] (so that equal corners average exactly)."""
    from trimesh.visual.color import to_rgba

    rgba = np.asarray(to_rgba(colors), np.float64).reshape(-1, 4)
    if len(rgba) == 1:
        rgba = np.repeat(rgba, count, axis=0)
    if len(rgba) != count:
        raise ValueError(f"{len(rgba)} {what} colours, expected 1 or {count}")
    return rgba[:, :3]


def _material_colors(visual, count: int):
    """Per-vertex RGB in [0, 255] of a trimesh ``TextureVisuals``: its texture at each
    vertex's UV (its mean colour without UVs), or without a texture its material's colour
    (glTF ``baseColorFactor``, white if none; OBJ ``Kd``), times its vertex colours where
    it has them; and the UVs and texture for the ray caster (``None`` without both)."""
    from trimesh.visual.color import uv_to_color
    from trimesh.visual.material import PBRMaterial, SimpleMaterial

    material = visual.material
    if isinstance(material, PBRMaterial):
        image, color = material.baseColorTexture, material.baseColorFactor
    elif isinstance(material, SimpleMaterial):
        image, color = material.image, material.diffuse
    else:
        raise ValueError(f"material of type {type(material).__name__} is not supported; "
                         f"allowed: SimpleMaterial (OBJ), PBRMaterial (glTF)")
    uvs = texture = None
    if image is None:
        colors = _rgb((255, 255, 255) if color is None else color, count, "material")
    else:
        texture = np.asarray(image.convert("RGB"), np.uint8)
        if visual.uv is None:
            colors = _rgb(texture.reshape(-1, 3).mean(axis=0) / 255, count, "texture")
            texture = None
        else:
            uvs = np.asarray(visual.uv, np.float64)
            if uvs.shape != (count, 2) or not np.all(np.isfinite(uvs)):
                raise ValueError(f"texture coordinates must be finite, one (u, v) per "
                                 f"vertex: got shape {uvs.shape} for {count} vertices")
            colors = _rgb(uv_to_color(uvs, image), count, "texture")
    if "color" in visual.vertex_attributes:
        colors = colors * _rgb(visual.vertex_attributes["color"], count, "vertex") / 255
    return colors, uvs, texture


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


def _flag(text: str) -> bool:
    if text not in ("0", "1", "true", "false"):
        raise ValueError("expected 0, 1, true or false")
    return text in ("1", "true")


def _floats(*counts: int) -> Callable[[str], tuple[float, ...]]:
    """A reader of ``counts`` (one of them) comma-separated numbers."""
    def read(text: str) -> tuple[float, ...]:
        try:
            values = tuple(float(v) for v in text.split(","))
        except ValueError:
            values = ()
        if len(values) not in counts:
            raise ValueError("expected a number" if counts == (1,) else
                             f"expected {' or '.join(map(str, counts))} comma-separated "
                             f"numbers")
        return values
    return read


def _bounds(text: str) -> tuple[tuple[float, ...], tuple[float, ...]]:
    values = _floats(4)(text)
    return values[:2], values[2:]


def _names(text: str) -> tuple[str, ...]:
    names = tuple(text.split(","))
    if not all(names):
        raise ValueError("expected comma-separated part names, none empty")
    return names


#: How the text of each ``"mesh:PATH?key=value"`` option becomes a
#: :class:`MeshOptions` value (which then checks it).
SPEC_OPTIONS: dict[str, Callable[[str], object]] = {
    "scale": lambda text: _floats(1)(text)[0],
    "up": str,
    "offset": _floats(3),
    "bounds": _bounds,
    "fence": _flag,
    "ground_plane": _flag,
    "ground_color": _floats(3, 4),
    "sky_color": _floats(3),
    "height_band": _floats(2),
    "collision": _flag,
    "no_collision": _names,
}


def parse_mesh_spec(spec: str) -> tuple[str, MeshOptions]:
    """``"mesh:PATH?key=value&..."`` -> (path, its :class:`MeshOptions`); a bad, unknown,
    repeated or empty option is a ``ValueError`` naming it and what is allowed."""
    path, _, query = spec[len("mesh:"):].partition("?")
    if not path:
        raise ValueError(f"scene {spec!r}: give a file after 'mesh:', e.g. 'mesh:world.obj'")
    options: dict[str, object] = {}
    try:
        for field in query.split("&") if query else ():
            key, equals, text = field.partition("=")
            if not key:
                what = (f"option {field!r} has no name" if field else
                        "an empty option (nothing between '?' or '&' and the next '&' or "
                        "the end)")
                raise ValueError(f"{what}: write options as key=value joined by '&', "
                                 f"mesh:PATH?option=value&option=value, e.g. "
                                 f"mesh:PATH?scale=0.01&up=y")
            _check_option_name(key)
            if not equals:
                raise ValueError(f"option {key!r} has no value: write {key}=VALUE")
            if key in options:
                raise ValueError(f"option {key!r} is given twice; give each option once")
            try:
                options[key] = SPEC_OPTIONS[key](text)
            except ValueError as error:
                raise ValueError(f"bad {key}={text!r}: {error}") from None
        return path, MeshOptions(**options)
    except ValueError as error:
        raise ValueError(f"scene {spec!r}: {error}") from None


def mesh_scene_from_spec(spec: str) -> MeshScene:
    """The :class:`MeshScene` named by a ``"mesh:PATH?..."`` string; a file is read once
    per process while it is unchanged."""
    path, options = parse_mesh_spec(spec)
    try:
        _mesh_file(path)
    except ValueError as error:
        raise ValueError(f"scene {spec!r}: {error}") from None
    stat = os.stat(path)
    return _cached_scene(os.path.abspath(path), stat.st_mtime_ns, stat.st_size, options)


@lru_cache(maxsize=8)
def _cached_scene(path: str, mtime: int, size: int, options: MeshOptions) -> MeshScene:
    return MeshScene.from_file(path, **vars(options))
