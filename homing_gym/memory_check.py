"""Memory over many procedural worlds: resident memory of one env that draws a new world
at every reset.

``python -m homing_gym.memory_check`` makes one LocalHoming-v0 env in a procedural scene
(``--scene``, default ``random_nature``), resets it ``--worlds`` times with a new world
each time (seeds 0, 1, 2, ...; ``episodes_per_world=1``) and prints the process's
resident memory (MiB) every ``--every`` worlds, then the growth after the first
``--every`` worlds (the allocator's and the caches' warm-up). Needs ``psutil``.
"""

from __future__ import annotations

import gc
import sys

import gymnasium as gym

from homing_gym.cli import command_parser
from homing_gym.scenes import scene_factory


def resident_mib() -> float:
    """This process's resident memory, MiB."""
    import psutil

    return psutil.Process().memory_info().rss / 2**20


def memory_curve(scene: str = "random_nature", worlds: int = 1000, every: int = 100,
                 **env_kwargs) -> list[tuple[int, float]]:
    """``(worlds drawn, resident MiB)`` after every ``every`` of ``worlds`` new worlds in
    one LocalHoming-v0 env of procedural ``scene`` (``env_kwargs``: more env options),
    starting with the count 0 right after the env's first reset."""
    env = gym.make("homing_gym/LocalHoming-v0", scene=scene, episodes_per_world=1,
                   **env_kwargs)
    try:
        env.reset(seed=0)
        curve = [(0, resident_mib())]
        for world in range(1, worlds + 1):
            env.reset(seed=world)
            if world % every == 0:
                gc.collect()
                curve.append((world, resident_mib()))
    finally:
        env.close()
    return curve


def main(argv: list[str] | None = None) -> int:
    parser = command_parser("python -m homing_gym.memory_check", __doc__)
    parser.add_argument("--scene", default="random_nature",
                        help="a procedural scene (one that draws a new world every reset)")
    parser.add_argument("--worlds", type=int, default=1000, help="new worlds to draw")
    parser.add_argument("--every", type=int, default=100, help="print memory every N worlds")
    parser.add_argument("--renderer", default="raycast", choices=["raycast", "tiny"])
    args = parser.parse_args(argv)
    if not 1 <= args.every <= args.worlds <= 10**6:
        parser.error(f"need 1 <= --every <= --worlds <= 1000000, got --every {args.every} "
                     f"--worlds {args.worlds}")
    try:
        procedural = scene_factory(args.scene).randomised
    except ValueError as err:
        parser.error(f"--scene: {err}")
    if not procedural:
        parser.error(f"--scene {args.scene!r} is not procedural (it draws no new worlds)")
    try:
        import psutil  # noqa: F401
    except ImportError:
        parser.error("psutil is needed to read resident memory (pip install psutil)")
    curve = []
    for world, mib in memory_curve(args.scene, args.worlds, args.every,
                                   renderer=args.renderer, panorama_shape=(16, 64)):
        print(f"{world:>8} worlds  {mib:8.1f} MiB", flush=True)
        curve.append(mib)
    if len(curve) > 2:
        print(f"growth after the first {args.every} worlds: {curve[-1] - curve[1]:+.1f} MiB "
              f"over {args.worlds - args.every} worlds")
    return 0


if __name__ == "__main__":
    sys.exit(main())
