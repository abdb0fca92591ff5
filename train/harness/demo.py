"""``homing-demo``: one episode as pictures (LocalHoming-v0 in the arena unless
``--env``, ``--env-kwargs`` or ``--scene`` say otherwise).

Writes into ``--out``:

* ``demo.png``: the last frame of ``render("rgb_array")`` (top-down map with the path,
  current and goal panoramas);
* ``demo.gif``: the whole episode, animated;
* ``views.png``: what the camera gives at the start pose: the panorama with its bearing
  axis, the ``omni`` ring image and the horizon ``signature``.

The robot is driven by the ``oracle`` controller (true pose, for illustration only); the
comparison of real methods is the job of ``homing-eval`` and ``homing-compare``.
"""

from __future__ import annotations

import sys
from pathlib import Path

import gymnasium as gym
import imageio.v2 as imageio
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from tqdm import tqdm  # noqa: E402

import homing_gym  # noqa: E402,F401
from homing_gym.cli import (add_env_arguments, command_parser,  # noqa: E402
                            env_kwargs_from_args, seed_value)
from homing_gym.render.panorama import bearing_column  # noqa: E402
from homing_train import DEFAULT_ENV  # noqa: E402
from homing_train.harness.evaluate import check_env_id  # noqa: E402
from homing_train.harness.rollout import prepare_policy, rollout  # noqa: E402
from homing_gym.outputs import output_dir_argument, save_figure  # noqa: E402

#: The observation keys the views figure shows (added to any ``obs_keys`` given).
VIEW_KEYS = ("panorama", "goal", "omni", "signature")


def run_episode(env: gym.Env, seed: int, controller_name: str = "oracle"):
    """Frames and final info of one episode driven by a registered controller."""
    import homing_baselines

    controller = homing_baselines.make(controller_name)
    prepare_policy(controller, env)
    frames = []
    limit = env.spec.max_episode_steps or 500
    bar = tqdm(total=limit, desc=f"demo episode (seed {seed})")

    def record(t, obs, action, info) -> None:
        frames.append(env.render())
        bar.update()

    run = rollout(env, controller, seed, on_step=record)
    bar.close()
    frames.append(env.render())
    return frames, run.info


def views_figure(env: gym.Env, seed: int, path: Path) -> None:
    """Panorama with bearings, ring image and signature at the start of episode ``seed``."""
    obs, _ = env.reset(seed=seed)
    pano, ring, sig = obs["panorama"], obs["omni"], obs["signature"]
    H, W = pano.shape[:2]
    fig = plt.figure(figsize=(11, 4.2), constrained_layout=True)
    grid = fig.add_gridspec(2, 3)
    ax = fig.add_subplot(grid[0, :2])
    ax.imshow(pano, extent=(0, W, H, 0), interpolation="nearest")
    ticks = [180, 90, 0, -90]
    ax.set_xticks([bearing_column(np.radians(b), W) for b in ticks],
                  [f"{b}°" for b in ticks])
    ax.axhline(H / 2, color="yellow", lw=0.8, ls="--")
    ax.set_title("panorama: bearing (CCW from heading) on the x axis, horizon dashed")
    ax.set_yticks([])
    ax2 = fig.add_subplot(grid[1, :2])
    ax2.plot(np.arange(W) + 0.5, sig, color="k")
    ax2.set_xlim(0, W)
    ax2.set_xticks([bearing_column(np.radians(b), W) for b in ticks],
                   [f"{b}°" for b in ticks])
    ax2.set_ylabel("luminance")
    ax2.set_title("horizon signature (Hong et al. 1991 §2)")
    ax3 = fig.add_subplot(grid[:, 2])
    ax3.imshow(ring)
    ax3.set_title("omni ring image (heading up)")
    ax3.axis("off")
    save_figure(fig, path, dpi=90)
    plt.close(fig)


def main(argv: list[str] | None = None) -> int:
    parser = command_parser("homing-demo", __doc__)
    parser.add_argument("--out", default="demo", type=output_dir_argument,
                        help="output folder")
    parser.add_argument("--seed", type=seed_value, default=9)
    add_env_arguments(parser, DEFAULT_ENV)
    args = parser.parse_args(argv)
    try:
        kwargs = env_kwargs_from_args(args)
        kwargs["obs_keys"] = tuple(dict.fromkeys([*kwargs.get("obs_keys", ()), *VIEW_KEYS]))
        check_env_id(args.env)
        env = gym.make(args.env, render_mode="rgb_array", **kwargs)
    except (ValueError, gym.error.Error) as err:
        parser.error(str(err))
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    try:
        frames, info = run_episode(env, args.seed)
        imageio.imwrite(out / "demo.png", frames[-1])
        small = [f[::2, ::2] for f in frames[::2]]
        imageio.mimsave(out / "demo.gif", small, duration=0.2, loop=0)
        views_figure(env, args.seed, out / "views.png")
    finally:
        env.close()
    outcome = "reached the goal" if info["is_success"] else "did not reach the goal"
    print(f"episode {args.seed}: {outcome} in {len(frames) - 1} steps, final distance "
          f"{info['distance_to_goal']:.3f} m; wrote {out}/demo.png, demo.gif, views.png")
    return 0


if __name__ == "__main__":
    sys.exit(main())
