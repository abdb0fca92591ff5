"""The homing vector field (Yu & Kim 2011, Figs. 4 and 10) and its scores.

On a grid over the free floor of the scene of episode ``seed``, the robot is placed with
a random heading and the controller's first commanded motion direction
(:attr:`baselines.Controller.last_home_direction`, after a measuring step for methods
that take one) is drawn as an arrow. Scores:

* AAE: average angular error (degrees) between the commanded and the true (straight
  line) home direction;
* homeward component: mean cosine of that error (1: straight home, 0: chance);
* return ratio: share of grid starts from which the controller, run to the end of the
  episode, reaches home (arrow colour: green returned, red did not).

Command line (also ``python -m homing_train.harness.field``)::

    homing-field --policy oracle --env homing_gym/LocalHoming-v0 --grid 0.2 --out field.png
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
from dataclasses import asdict, dataclass, field
from typing import Any

import cv2
import gymnasium as gym
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.backend_bases import FigureCanvasBase  # noqa: E402

from homing_gym.cli import command_parser, env_kwargs_from_args  # noqa: E402
from homing_gym.geometry import wrap_angle  # noqa: E402
from homing_gym.paths import connected  # noqa: E402
from homing_gym.scenes.base import clearances  # noqa: E402
from homing_gym.render.topdown import MapCanvas, draw_pose, draw_scale_bar, draw_scene  # noqa: E402
from homing_train.harness.evaluate import (DEFAULT_ENV, add_policy_arguments,  # noqa: E402
                                           check_env_id, policy_from_args, run_episodes)
from homing_train.harness.palette import HOME_MARK  # noqa: E402
from homing_train.harness.policies import PolicySpec, policy_spec  # noqa: E402
from homing_train.harness.protocols import PROTOCOLS, protocol  # noqa: E402
from homing_train.harness.rollout import prepare_policy, rollout  # noqa: E402
from homing_gym.outputs import (OutputLock, output_file_argument,  # noqa: E402
                                save_figure, write_text_atomic)
from homing_train.pool import WorkerDiedError, end_stopped_command  # noqa: E402

# colour-blind-safe (Okabe & Ito): returned blue, not returned vermillion, unknown grey
RETURNED, FAILED, UNKNOWN = (0, 114, 178), (213, 94, 0), (110, 110, 110)


@dataclass
class FieldResult:
    """Grid points (x, y, heading; metres, radians), commanded world directions (radians;
    NaN where the controller stopped), true home directions, and the scores."""

    policy: str
    env_id: str
    seed: int
    grid: float
    home: list[float]
    points: list[list[float]]
    commanded: list[float]
    true_direction: list[float]
    returned: list[bool] | None
    aae_deg: float
    homeward: float
    return_ratio: float | None
    extra: dict[str, Any] = field(default_factory=dict)


#: Most grid points a field may have (each one runs the controller once).
MAX_GRID_POINTS = 20_000


def grid_points(scene, home, spacing: float, margin: float, exclude: float,
                path_radius: float) -> np.ndarray:
    """Cell centres of a ``spacing`` grid over the scene bounds with at least ``margin`` m
    clearance, more than ``exclude`` m from home and joined to home by a path for a disc
    of ``path_radius`` m (:func:`homing_gym.paths.connected`: the starts the task itself
    could draw; a point in a closed pocket has no way home)."""
    if not spacing > 0:
        raise ValueError(f"grid spacing must be positive metres, got {spacing}")
    (xmin, ymin), (xmax, ymax) = scene.bounds
    cells = math.ceil((xmax - xmin) / spacing) * math.ceil((ymax - ymin) / spacing)
    if cells > MAX_GRID_POINTS:
        raise ValueError(f"grid spacing {spacing} m over the {xmax - xmin:g} x {ymax - ymin:g} m "
                         f"of scene {scene.name!r} gives {cells} points; at most "
                         f"{MAX_GRID_POINTS} (give a coarser grid)")
    xs = np.arange(xmin + spacing / 2, xmax, spacing)
    ys = np.arange(ymin + spacing / 2, ymax, spacing)
    gx, gy = np.meshgrid(xs, ys)                        # row by row: y outer, x inner
    pts = np.column_stack([gx.ravel(), gy.ravel()])
    keep = (clearances(scene, pts) >= margin) & (
        np.hypot(pts[:, 0] - home[0], pts[:, 1] - home[1]) > exclude)
    return np.array([p for p in pts[keep] if connected(scene, p, home, path_radius)],
                    dtype=np.float64).reshape(-1, 2)


PROBE_STEPS = 40


def first_home_decision(env: gym.Env, controller, pose, seed: int,
                        max_steps: int = PROBE_STEPS,
                        home=None) -> tuple[np.ndarray, float | None]:
    """Start an episode at ``pose`` and run the controller until it states a home
    direction (at once for most methods; after its measuring step for distance estimation,
    as in Yu & Kim Fig. 10). Returns the robot pose at that decision and the direction
    (robot frame, radians), or ``None`` if none came within ``max_steps`` steps."""
    decision: list = []

    def stated(t, obs, action, info) -> bool:
        if controller.last_home_direction is None:
            return False
        decision.append((np.asarray(info["pose"], dtype=np.float64).copy(),
                         controller.last_home_direction))
        return True

    options = {"start": [float(v) for v in pose]}
    if home is not None:
        options["home"] = [float(v) for v in home]
    rollout(env, controller, seed, options, on_step=stated, max_steps=max_steps)
    return decision[0] if decision else (np.asarray(pose, dtype=np.float64), None)


def homing_field(policy, env_id: str = DEFAULT_ENV, grid: float = 0.2, seed: int = 0,
                 env_kwargs: dict[str, Any] | None = None, margin: float = 0.22,
                 run_to_end: bool = True, workers: int = 1, progress: bool = True,
                 params: dict[str, Any] | None = None, home=None) -> FieldResult:
    """Compute the vector field of ``policy`` in the scene and home of episode ``seed``
    (``home``: a fixed home pose (x, y, yaw) instead)."""
    spec: PolicySpec = policy_spec(policy, params)
    if spec.kind != "controller":
        raise ValueError("homing-field needs a scripted controller that reports its home "
                         "direction (Controller.last_home_direction); SB3 models do not")
    check_env_id(env_id)
    env_kwargs = dict(env_kwargs or {})
    env = gym.make(env_id, **env_kwargs)
    try:
        _, info = env.reset(seed=seed, options=None if home is None else {"home": home})
        u = env.unwrapped
        home = np.asarray(info["home_pose"], dtype=np.float64)
        radius = getattr(u.task, "success_radius", 0.15)
        xy = grid_points(u.scene, home, grid, margin, radius, u.task.path_radius)
        if len(xy) == 0:
            raise ValueError(f"no grid point with {margin} m clearance and a path home at "
                             f"spacing {grid} m")
        headings = np.random.default_rng(seed).uniform(-np.pi, np.pi, len(xy))
        points = np.column_stack([xy, headings])
        controller = spec.build()
        prepare_policy(controller, env)
        commanded, true_dir = [], []
        for pose in points:
            decision_pose, direction = first_home_decision(env, controller, pose, seed,
                                                           home=home)
            commanded.append(math.nan if direction is None
                             else wrap_angle(decision_pose[2] + direction))
            true_dir.append(math.atan2(home[1] - decision_pose[1], home[0] - decision_pose[0]))
        scene = u.scene
    finally:
        env.close()
    cmd, true = np.array(commanded), np.array(true_dir)
    valid = ~np.isnan(cmd)
    err = np.abs(wrap_angle(cmd[valid] - true[valid])) if valid.any() else np.array([np.pi])
    returned = None
    if run_to_end:
        records = run_episodes(spec, env_id, env_kwargs,
                               [(seed, p, None if home is None else tuple(home))
                                for p in points],
                               workers, progress, desc=f"{spec.label} field")
        returned = [r.success for r in records]
    result = FieldResult(
        policy=spec.label, env_id=env_id, seed=seed, grid=grid, home=home.tolist(),
        points=points.round(4).tolist(), commanded=[float(c) for c in cmd],
        true_direction=true.tolist(), returned=returned,
        aae_deg=float(np.degrees(err.mean())), homeward=float(np.cos(err).mean()),
        return_ratio=None if returned is None else float(np.mean(returned)),
        extra={"stopped_points": int((~valid).sum())})
    result.extra["scene"] = scene
    return result


def plot_field(result: FieldResult, path: str, size: int = 480) -> None:
    """Arrows of the commanded directions on the top-down map."""
    scene = result.extra["scene"]
    canvas = MapCanvas(scene, size)
    img = draw_scene(scene, canvas)
    length = 0.4 * result.grid
    for k, (x, y, _) in enumerate(result.points):
        colour = UNKNOWN if result.returned is None else (RETURNED if result.returned[k] else FAILED)
        c = result.commanded[k]
        if math.isnan(c):
            cv2.circle(img, canvas.px(x, y), 3, colour, -1, cv2.LINE_AA)
            continue
        tail = canvas.px(x - length / 2 * math.cos(c), y - length / 2 * math.sin(c))
        tip = canvas.px(x + length / 2 * math.cos(c), y + length / 2 * math.sin(c))
        cv2.arrowedLine(img, tail, tip, colour, 2, cv2.LINE_AA, tipLength=0.35)
    draw_pose(img, canvas, result.home, 0.16, HOME_MARK, filled=False)
    draw_scale_bar(img, canvas)
    fig, ax = plt.subplots(figsize=(5, 6.0), dpi=100)
    ax.imshow(img)
    ax.axis("off")
    title = (f"{result.policy}: AAE {result.aae_deg:.1f} deg, homeward "
             f"{result.homeward:.2f}\nAAE: average angle between commanded and true home "
             f"direction;\nhomeward: its mean cosine; ring: home")
    if result.return_ratio is not None:
        title += (f"\nreturn ratio {100 * result.return_ratio:.0f}% "
                  f"(blue: returned, vermillion: not)")
    ax.set_title(title, fontsize=10)
    fig.tight_layout()
    save_figure(fig, path)
    plt.close(fig)


def picture_argument(text: str) -> str:
    """``--out``'s type: a picture file that can be written, in a format matplotlib
    writes (named by its extension), with its scores' ``.json`` beside."""
    output_file_argument(text)
    output_file_argument(os.path.splitext(text)[0] + ".json")
    formats = FigureCanvasBase.get_supported_filetypes()
    if os.path.splitext(text)[1].lstrip(".").lower() not in formats:
        raise argparse.ArgumentTypeError(
            f"{text!r}: the picture's format comes from its extension; use one of "
            f"{', '.join('.' + f for f in sorted(formats))}")
    return text


def main(argv: list[str] | None = None) -> int:
    parser = command_parser("homing-field", __doc__)
    add_policy_arguments(parser, controllers_only=True)
    parser.add_argument("--protocol", choices=sorted(PROTOCOLS),
                        help="the field in this protocol's first setting: its env, env kwargs "
                        "and its first episode's home (with --seed: of that draw)")
    parser.add_argument("--grid", type=float, default=0.2, help="grid spacing (m)")
    parser.add_argument("--no-return", action="store_true",
                        help="skip the return-ratio runs (arrows only, fast)")
    parser.add_argument("--out", required=True, type=picture_argument,
                        help="PNG path (scores go to a .json beside)")
    args = parser.parse_args(argv)
    try:
        with OutputLock(args.out):          # one run at a time on a picture
            return _field(args)
    except ValueError as err:
        parser.exit(2, f"homing-field: error: {err}\n")
    except (WorkerDiedError, KeyboardInterrupt) as err:   # Ctrl-C, SIGTERM, SIGHUP too
        end_stopped_command(parser, err, f"{args.out} was not written")


def _field(args) -> int:
    """Compute the field the options ask for, draw it and write its scores."""
    env_kwargs = env_kwargs_from_args(args)
    env_id, seed, home, drawn_in = args.env, args.seed or 0, None, None
    if args.protocol:
        if args.env != DEFAULT_ENV or env_kwargs:
            raise ValueError("--protocol fixes the env, its kwargs and the home; drop "
                             "--env/--env-kwargs/--scene")
        chosen = protocol(args.protocol)
        if args.seed is not None:
            chosen = chosen.reseeded(args.seed)
        setting = chosen.settings[0]
        env_id, env_kwargs = setting.env_id, setting.kwargs()
        seed, _, home = setting.episode_tasks(1, chosen.seed)[0]
        drawn_in = chosen.label
    result = homing_field(policy_from_args(args), env_id, args.grid, seed,
                          env_kwargs, run_to_end=not args.no_return,
                          workers=args.workers, progress=not args.quiet, home=home)
    plot_field(result, args.out)
    doc = asdict(result)
    doc["extra"] = {k: v for k, v in result.extra.items() if k != "scene"}
    doc["env_kwargs"] = env_kwargs
    if drawn_in:
        doc["protocol"] = drawn_in          # with the note when not its canonical draw
    write_text_atomic(os.path.splitext(args.out)[0] + ".json", json.dumps(doc))
    ratio = "n/a" if result.return_ratio is None else f"{100 * result.return_ratio:.1f}%"
    print(f"{result.policy}: {len(result.points)} grid points, AAE {result.aae_deg:.1f} deg, "
          f"homeward component {result.homeward:.3f}, return ratio {ratio}")
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
