"""An example natural world to bring in as a user would: tussock grass and rocks on sand.

``python -m homing_gym.scenes.tussocks tussocks.ply`` writes it as one mesh with per-face
colours (the form in which natural worlds are often shared); ``tussocks.glb`` keeps three
named parts, ``sand``, ``grass`` and ``rocks``, so that ``no_collision=grass`` lets the
robot drive through the grass and still bump into the rocks. The field is ``side`` metres
square, centred on the origin, in metres with z up: a sand floor at z = 0 (two
triangles), ``blades`` grass blades in tussocks (:func:`tussock_blades`) and ``rocks``
lumpy rocks (closed icospheres 0.2-0.5 m across). The benchmark's ``grass10k`` and
``grass50k`` worlds are fields of the same blades.
"""

from __future__ import annotations

import numpy as np
import trimesh

from homing_gym.scenes.mesh_example import write_parts

#: RGB (0-1) of the sand floor.
SAND = (0.76, 0.66, 0.45)


def tussock_blades(blades: int, seed: int, half: float) -> tuple[np.ndarray, np.ndarray]:
    """``blades`` grass blades in clumps of 10-60 of up to 15 cm radius, centred within
    ``half`` metres of the origin (in x and in y), each one thin triangle: 1-4 cm wide at
    the ground, 5-90 cm tall, leaning outwards by up to a fifth of its height. Returns the
    triangles' corners ``(blades, 3, 3)`` (metres) and their colours ``(blades, 3)`` (RGB,
    0-1, greens)."""
    if not (isinstance(blades, (int, np.integer)) and blades >= 1):
        raise ValueError(f"blades must be an integer >= 1, got {blades!r}")
    rng = np.random.default_rng(seed)
    sizes = []
    while sum(sizes) < blades:
        sizes.append(int(rng.integers(10, 61)))
    sizes[-1] -= sum(sizes) - blades
    clump = np.repeat(np.arange(len(sizes)), sizes)
    centre = rng.uniform(-half, half, (len(sizes), 2))[clump]
    tallest = rng.uniform(0.2, 0.9, len(sizes))[clump]
    offset = rng.uniform(0, 0.15, blades)[:, None] * _unit(rng.uniform(0, 2 * np.pi, blades))
    foot = centre + offset
    width = rng.uniform(0.01, 0.04, blades)[:, None] * _unit(rng.uniform(0, 2 * np.pi, blades))
    height = rng.uniform(0.05, 1.0, blades) * (tallest - 0.05) + 0.05
    outwards = offset / np.maximum(np.linalg.norm(offset, axis=1, keepdims=True), 1e-9)
    lean = rng.uniform(0, 0.2, blades)[:, None] * height[:, None] * outwards
    zero = np.zeros((blades, 1))
    corners = np.stack([np.hstack([foot - width / 2, zero]), np.hstack([foot + width / 2, zero]),
                        np.hstack([foot + lean, height[:, None]])], 1)
    colors = np.column_stack([rng.uniform(0.2, 0.5, blades), rng.uniform(0.45, 0.8, blades),
                              rng.uniform(0.1, 0.3, blades)])
    return corners, colors


def _unit(angle: np.ndarray) -> np.ndarray:
    """Unit vectors ``(n, 2)`` at the angles ``angle`` (radians)."""
    return np.column_stack([np.cos(angle), np.sin(angle)])


def _rgba(colors: np.ndarray) -> np.ndarray:
    return np.column_stack([np.round(255 * np.asarray(colors)), np.full(len(colors), 255)]
                           ).astype(np.uint8)


def tussock_field(blades: int = 3000, rocks: int = 12, side: float = 8.0,
                  seed: int = 0) -> dict[str, trimesh.Trimesh]:
    """The field's parts by name, ``sand``, ``grass`` and ``rocks`` (see the module doc),
    with per-face colours; rocks keep 1 m from the centre."""
    rng = np.random.default_rng(seed)
    half = side / 2
    sand = trimesh.Trimesh([(-half, -half, 0), (half, -half, 0), (half, half, 0),
                            (-half, half, 0)], [(0, 1, 2), (0, 2, 3)], process=False)
    sand.visual.face_colors = _rgba([SAND, SAND])
    corners, colors = tussock_blades(blades, seed, half - 0.2)
    grass = trimesh.Trimesh(corners.reshape(-1, 3), np.arange(3 * blades).reshape(-1, 3),
                            process=False)
    grass.visual.face_colors = _rgba(colors)
    stones = []
    while len(stones) < rocks:
        x, y = rng.uniform(-half + 0.5, half - 0.5, 2)
        if np.hypot(x, y) > 1.0:
            rock = trimesh.creation.icosphere(subdivisions=1)
            size = rng.uniform(0.1, 0.25)
            rock.apply_scale((size, size, rng.uniform(0.6, 1.2) * size))
            rock.apply_translation((x, y, 0.5 * size))
            rock.visual.face_colors = _rgba(np.tile(rng.uniform(0.35, 0.6, 3), (len(rock.faces), 1)))
            stones.append(rock)
    return {"sand": sand, "grass": grass, "rocks": trimesh.util.concatenate(stones)}


def write_tussock_field(path, **options) -> None:
    """Write :func:`tussock_field` (``options``) to ``path``: a GLB (or glTF) keeps the
    three named parts, other formats trimesh writes (PLY, OBJ) get one mesh."""
    write_parts(tussock_field(**options), path)


def main(argv: list[str] | None = None) -> int:
    """Write the example field to the path given."""
    from homing_gym.cli import command_parser
    parser = command_parser("python -m homing_gym.scenes.tussocks", __doc__)
    parser.add_argument("out", help="the file to write: .glb/.gltf keeps the named parts, "
                        ".ply/.obj one mesh with per-face colours")
    parser.add_argument("--blades", type=int, default=3000, help="grass blades")
    parser.add_argument("--rocks", type=int, default=12, help="rocks")
    parser.add_argument("--seed", type=int, default=0, help="seed of the layout")
    args = parser.parse_args(argv)
    try:
        write_tussock_field(args.out, blades=args.blades, rocks=args.rocks, seed=args.seed)
    except ValueError as err:
        parser.exit(2, f"{parser.prog}: error: {err}\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
