"""Check a world before using it: where the robot can go, and what it sees.

``python -m homing_gym.freespace --scene SCENE --out DIR`` makes the env with the scene
(any scene an env takes: a name, one registered by ``--import``, or ``mesh:PATH?...``),
draws its episode 0, and writes ``DIR/freespace.png`` (the scene from above with the
floor the task draws episodes on: the free regions at the task's ``path_radius``, the
largest green, the others in other colours, blocked floor grey, a scale bar, and
episode 0's home and start) and ``DIR/panorama.png`` (the panorama at episode 0's start,
and the goal snapshot). It prints the world's size, its triangles, the free share of
its floor and its regions. A world whose floor splits into regions is fine for
episodes (start and home are always drawn in one), but a large region the robot should
not be in (under a hill, inside a building) means the bounds or ``offset`` need a
change.
"""

from __future__ import annotations

import os
import sys
from dataclasses import dataclass

import cv2
import gymnasium as gym
import numpy as np

from homing_gym.cli import add_env_arguments, command_parser, env_kwargs_from_args
from homing_gym.paths import RESOLUTION, occupancy, regions
from homing_gym.scenes.base import Scene
from homing_gym.render.topdown import (HOME, ROBOT, MapCanvas, compose_frame, draw_pose,
                                draw_scale_bar, draw_scene)

#: RGB of the largest free region, of the other regions (in turn) and of blocked floor.
LARGEST = (120, 200, 120)
OTHERS = ((240, 170, 60), (90, 150, 230), (220, 100, 160), (160, 120, 220), (90, 200, 200))
BLOCKED = (150, 150, 150)
#: Opacity of the region colours over the scene drawing.
ALPHA = 0.45


@dataclass(frozen=True)
class FreeSpace:
    """The floor of a scene for a disc of ``radius`` metres on the episodes' grid:
    ``area`` (m^2, the bounds), ``free_share`` (of the bounds' floor), ``region_shares``
    (each region's share of the free floor, largest first)."""

    scene: str
    radius: float
    bounds: tuple[tuple[float, float], tuple[float, float]]
    triangles: int
    area: float
    free_share: float
    region_shares: tuple[float, ...]

    def summary(self) -> str:
        """Plain-text lines for the terminal."""
        (xmin, ymin), (xmax, ymax) = self.bounds
        shares = ", ".join(f"{100 * s:.1f}%" for s in self.region_shares[:6])
        more = len(self.region_shares) - 6
        return "\n".join([
            f"scene {self.scene}: bounds x {xmin:.2f}..{xmax:.2f}, y {ymin:.2f}..{ymax:.2f} m "
            f"({xmax - xmin:.1f} x {ymax - ymin:.1f} m), {self.triangles:,} mesh triangles",
            f"free for a disc of {self.radius:.2f} m: {100 * self.free_share:.1f}% of the "
            f"floor, in {len(self.region_shares)} region(s): {shares}"
            + (f" and {more} more" if more > 0 else "")])


def free_space(scene: Scene, radius: float) -> FreeSpace:
    """The :class:`FreeSpace` of ``scene`` for a disc of ``radius`` metres."""
    free, _ = occupancy(scene, radius, RESOLUTION)
    sizes = np.bincount(regions(scene, radius, RESOLUTION).ravel())[1:]
    (xmin, ymin), (xmax, ymax) = scene.bounds
    total = max(int(free.sum()), 1)
    return FreeSpace(scene.name, float(radius), scene.bounds,
                     int(sum(len(p.faces) for p in scene.meshes)),
                     float((xmax - xmin) * (ymax - ymin)), float(free.mean()),
                     tuple(float(s) / total for s in sorted(sizes, reverse=True)))


def free_space_image(scene: Scene, radius: float, size: int = 520) -> np.ndarray:
    """The scene from above (:func:`~homing_gym.render.topdown.draw_scene`) under the free
    regions for a disc of ``radius`` metres (largest :data:`LARGEST`, the others
    :data:`OTHERS` by size, blocked :data:`BLOCKED`) and a scale bar; RGB uint8."""
    canvas = MapCanvas(scene, size)
    img = draw_scene(scene, canvas)
    labels = regions(scene, radius, RESOLUTION)
    _, (x0, y0) = occupancy(scene, radius, RESOLUTION)
    sizes = np.bincount(labels.ravel())
    sizes[0] = 0
    palette = np.zeros((len(sizes), 3))
    palette[0] = BLOCKED
    for k, label in enumerate(np.argsort(sizes)[::-1][:np.count_nonzero(sizes)]):
        palette[label] = LARGEST if k == 0 else OTHERS[(k - 1) % len(OTHERS)]
    v, u = np.mgrid[0:size, 0:size]                       # pixel rows, columns -> floor
    x = canvas.cx + (u - size / 2) / canvas.scale
    y = canvas.cy - (v - size / 2) / canvas.scale
    i = np.rint((x - x0) / RESOLUTION).astype(int)
    j = np.rint((y - y0) / RESOLUTION).astype(int)
    inside = (i >= 0) & (i < labels.shape[0]) & (j >= 0) & (j < labels.shape[1])
    colour = palette[labels[i[inside], j[inside]]]
    img[inside] = ((1 - ALPHA) * img[inside] + ALPHA * colour).astype(np.uint8)
    span = max(scene.size)
    draw_scale_bar(img, canvas, float(10 ** np.floor(np.log10(span / 3))))
    return img


def main(argv: list[str] | None = None) -> int:
    parser = command_parser("python -m homing_gym.freespace", __doc__)
    add_env_arguments(parser, "homing_gym/LocalHoming-v0")
    parser.add_argument("--seed", type=int, default=0, help="the episode drawn and shown")
    parser.add_argument("--out", required=True, help="folder for freespace.png, panorama.png")
    args = parser.parse_args(argv)
    if os.path.exists(args.out) and not os.path.isdir(args.out):
        parser.error(f"--out {args.out!r} is a file; give a folder")
    try:
        env = gym.make(args.env, **env_kwargs_from_args(args))
    except ValueError as err:
        parser.exit(2, f"{parser.prog}: error: {err}\n")
    try:
        obs, info = env.reset(seed=args.seed)
        u = env.unwrapped
        radius = u.task.path_radius
        found = free_space(u.scene, radius)
        os.makedirs(args.out, exist_ok=True)
        img = free_space_image(u.scene, radius)
        canvas = MapCanvas(u.scene, img.shape[0])
        draw_pose(img, canvas, info["home_pose"], 0.16, HOME, filled=False)
        draw_pose(img, canvas, info["start_pose"], 0.16, ROBOT)
        cv2.imwrite(os.path.join(args.out, "freespace.png"), img[:, :, ::-1])
        frame = compose_frame(img, obs["panorama"], obs.get("goal", 0 * obs["panorama"]),
                              f"(episode {args.seed})")
        cv2.imwrite(os.path.join(args.out, "panorama.png"), frame[:, :, ::-1])
    finally:
        env.close()
    print(found.summary())
    print(f"episode {args.seed}: home {np.round(info['home_pose'][:2], 2).tolist()}, start "
          f"{np.round(info['start_pose'][:2], 2).tolist()} m; wrote "
          f"{args.out}/freespace.png, {args.out}/panorama.png")
    return 0


if __name__ == "__main__":
    sys.exit(main())
