"""An example mesh world to try ``"mesh:PATH"`` with: a furnished room as a GLB file.

``python -m homing_gym.scenes.mesh_example room.glb`` writes it; then
``gym.make("homing_gym/LocalHoming-v0", scene="mesh:room.glb")``. The room is 6 x 4 m
(inner wall faces at x = +-3, y = +-2 m, walls 1.5 m high), with a blue pillar (radius
0.2 m at (-1, -0.5)), a table whose top (0.70-0.74 m) is above the robot and whose four
legs (5 cm square) stand at (1.0, 0.5), (1.0, 1.1), (1.8, 0.5), (1.8, 1.1), and the room's
own floor at z = 0. Each piece is a named node of the file (``north``, ``pillar``,
``leg0``, ...). The tests use it as geometry with known answers.
"""

from __future__ import annotations

import os

import trimesh

#: The pillar: x, y, radius (metres).
PILLAR = (-1.0, -0.5, 0.2)
#: Centres (x, y) of the table's legs, and half their width (metres).
TABLE_LEGS = tuple((1.0 + dx, 0.5 + dy) for dx in (0.0, 0.8) for dy in (0.0, 0.6))
LEG_HALF = 0.025


def _box(extents, centre, rgb) -> trimesh.Trimesh:
    box = trimesh.creation.box(extents=extents)
    box.apply_translation(centre)
    box.visual.face_colors = [*rgb, 255]
    return box


def example_room_parts() -> dict[str, trimesh.Trimesh]:
    """The room's pieces by name (see the module doc)."""
    parts = {
        "north": _box((6, 0.1, 1.5), (0, 2.05, 0.75), (200, 180, 160)),
        "south": _box((6, 0.1, 1.5), (0, -2.05, 0.75), (180, 200, 160)),
        "east": _box((0.1, 4.2, 1.5), (3.05, 0, 0.75), (160, 180, 200)),
        "west": _box((0.1, 4.2, 1.5), (-3.05, 0, 0.75), (200, 160, 200)),
        "floor": _box((6, 4, 0.02), (0, 0, -0.01), (120, 120, 120)),
        "top": _box((0.9, 0.7, 0.04), (1.4, 0.8, 0.72), (140, 90, 40)),
    }
    for k, (x, y) in enumerate(TABLE_LEGS):
        parts[f"leg{k}"] = _box((2 * LEG_HALF, 2 * LEG_HALF, 0.7), (x, y, 0.35), (90, 60, 30))
    pillar = trimesh.creation.cylinder(radius=PILLAR[2], height=1.5, sections=64)
    pillar.apply_translation((PILLAR[0], PILLAR[1], 0.75))
    pillar.visual.face_colors = [20, 60, 200, 255]
    parts["pillar"] = pillar
    return parts


def write_parts(parts: dict[str, trimesh.Trimesh], path) -> None:
    """Write named meshes to ``path``: a GLB (or glTF) keeps one node per piece; other
    formats trimesh writes (OBJ, PLY, STL) get the pieces joined into one mesh. Missing
    folders of ``path`` are made."""
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    if str(path).lower().endswith((".glb", ".gltf")):
        scene = trimesh.Scene()
        for name, mesh in parts.items():
            scene.add_geometry(mesh, node_name=name, geom_name=name)
        scene.export(path)
    else:
        trimesh.util.concatenate(list(parts.values())).export(path)


def write_example_room(path) -> None:
    """Write the room to ``path`` (:func:`write_parts`)."""
    write_parts(example_room_parts(), path)


def main(argv: list[str] | None = None) -> int:
    """Write the example room to the path given."""
    from homing_gym.cli import command_parser
    parser = command_parser("python -m homing_gym.scenes.mesh_example", __doc__)
    parser.add_argument("out", help="the file to write: .glb/.gltf keeps the named parts, "
                        "any other format trimesh writes (.obj, .ply, ...) one mesh")
    write_example_room(parser.parse_args(argv).out)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
