"""TinyRenderer and the ray caster side by side: one panorama per built-in scene.

Writes ``SCENE.png`` per scene (TinyRenderer above, ray cast below, the same pose: the
start of episode ``--seed`` of LocalHoming-v0) and prints each pair's mean absolute
difference in grey levels.
"""

from __future__ import annotations

import sys
from pathlib import Path

import gymnasium as gym
import imageio.v2 as imageio
import numpy as np

import homing_gym  # noqa: F401  (registers the env ids)
from homing_gym.cli import command_parser, seed_value
from homing_gym.scenes import available_scenes
from homing_gym.outputs import output_dir_argument


def side_by_side(scene: str, seed: int, shape: tuple[int, int]) -> tuple[np.ndarray, float]:
    """TinyRenderer's panorama above the ray-cast one, and their mean absolute difference."""
    images = []
    for renderer in ("tiny", "raycast"):
        env = gym.make("homing_gym/LocalHoming-v0", scene=scene, renderer=renderer,
                       panorama_shape=shape, start_distance=(0.3, 0.8))
        env.reset(seed=seed)
        u = env.unwrapped
        images.append(u.render_panorama(u.pose))
        env.close()
    diff = float(np.abs(images[0].astype(int) - images[1].astype(int)).mean())
    gap = np.full((4, shape[1], 3), 255, np.uint8)
    return np.concatenate([images[0], gap, images[1]]), diff


def main(argv: list[str] | None = None) -> int:
    parser = command_parser("python -m homing_train.figures.renderers", __doc__)
    parser.add_argument("--out", type=output_dir_argument, default="docs/images/raycast", help="output folder")
    parser.add_argument("--seed", type=seed_value, default=2, help="episode whose start is shown")
    args = parser.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    for scene in available_scenes():
        image, diff = side_by_side(scene, args.seed, (60, 360))
        imageio.imwrite(out / f"{scene}.png", image)
        print(f"{scene}: mean absolute difference {diff:.1f} grey levels")
    return 0


if __name__ == "__main__":
    sys.exit(main())
