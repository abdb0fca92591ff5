"""Pictures of the procedural worlds and of a mesh world: for each, a few episodes' worlds
seen from above (1 m scale bar, the robot's start in blue) beside the ray-cast panorama
at the start and TinyRenderer's.

``python -m homing_train.figures.worlds --out docs/images/worlds`` writes
``random_rooms.png``, ``random_nature.png`` and ``mesh_room.png`` (the example room of
:mod:`homing_gym.scenes.mesh_example`, loaded as ``"mesh:PATH"``).
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

import gymnasium as gym
import imageio.v2 as imageio
import numpy as np

import homing_gym  # noqa: F401  (registers the env ids)
from homing_gym.cli import command_parser
from homing_gym.scenes.mesh_example import write_example_room
from homing_gym.render.topdown import (BG, ROBOT, MapCanvas, labelled, draw_pose, draw_scale_bar,
                                       draw_scene)
from homing_gym.outputs import output_dir_argument

PANORAMA = (60, 360)


def world_row(scene: str, seed: int, size: int = 240,
              renderers: tuple[str, ...] = ("raycast", "tiny")) -> np.ndarray:
    """The map of episode ``seed``'s world beside each renderer's start panorama (the
    first labelled with the seed and the camera's height)."""
    views, labels = {}, {}
    for renderer in renderers:
        env = gym.make("homing_gym/LocalHoming-v0", scene=scene, renderer=renderer,
                       panorama_shape=PANORAMA)
        env.reset(seed=seed)
        u = env.unwrapped
        views[renderer] = u.render_panorama(u.pose)
        labels[renderer] = renderer
        world, pose, height = u.scene, u.pose.copy(), u.camera.camera_height
        env.close()
    labels[renderers[0]] = f"seed {seed}: {renderers[0]}, camera {100 * height:.0f} cm up"
    canvas = MapCanvas(world, size)
    top = draw_scene(world, canvas)
    draw_pose(top, canvas, pose, 0.16, ROBOT)
    draw_scale_bar(top, canvas, 1.0)
    right = np.concatenate([labelled(views[r], labels[r], 2 * size) for r in renderers])
    height = max(size, right.shape[0])
    return np.concatenate([_pad(top, height), _pad(right, height)], axis=1)


def _pad(image: np.ndarray, height: int) -> np.ndarray:
    """``image`` with background rows below it up to ``height``."""
    fill = np.full((height - image.shape[0], image.shape[1], 3), BG, np.uint8)
    return np.concatenate([image, fill])


def main(argv: list[str] | None = None) -> int:
    parser = command_parser("python -m homing_train.figures.worlds", __doc__)
    parser.add_argument("--out", type=output_dir_argument, default="docs/images/worlds", help="output folder")
    parser.add_argument("--seeds", type=int, nargs="+", default=[0, 1, 2],
                        help="episodes of the procedural worlds")
    args = parser.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    for scene in ("random_rooms", "random_nature"):
        imageio.imwrite(out / f"{scene}.png",
                        np.concatenate([world_row(scene, seed) for seed in args.seeds]))
        print(f"wrote {out / scene}.png")
    with tempfile.TemporaryDirectory() as folder:
        room = Path(folder) / "room.glb"
        write_example_room(room)
        imageio.imwrite(out / "mesh_room.png", world_row(f"mesh:{room}", 0))
    print(f"wrote {out / 'mesh_room.png'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
