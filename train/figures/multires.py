"""Figures and numbers of docs/multires.md (Shiraishi & Sawasaki multi-resolution matching).

``python -m homing_train.figures.multires localisation --out docs/multires``: self-localisation
(§4(2-2), Fig. 10) at every point of a grid (``--spacing``, default 0.2 m) within 0.5 m
of each work location of the ``house`` and several headings (``--headings``), or at
``--random-poses N`` seeded random poses per location, with and without daily changes;
error distributions (``localisation.png``), summary (``localisation.json``) and localisations per second on
one core (the ``localise`` call alone, and with rendering the panorama).

``python -m homing_train.figures.multires travel --episodes 30 --out docs/multires``: seeded
``WorkLocations-v0`` episodes run by the ``multires`` controller; per episode the
distance to the target when the arrival decision (Fig. 5) declares "approximately at
the work location", the final stop distance and success (``travel.json``,
``travel.png``). ``--daily-changes S`` runs in today's changed house.

Ground truth (poses) is read here for measuring only; the controller sees observations.
"""

from __future__ import annotations

import json
import math
import sys
import time
from pathlib import Path

import gymnasium as gym
import numpy as np

import homing_baselines
import homing_gym
from homing_baselines.multires import LOCALISE
from homing_baselines.multires_localise import localise
from homing_gym.cli import command_parser, seed_value
from homing_gym.scenes.base import clearance
from homing_gym.teaching import FeatureMap
from homing_train.figures import MEASURED_WITH
from homing_train.harness.rollout import prepare_policy, rollout
from homing_gym.outputs import output_dir_argument, save_figure

ENV_ID = "homing_gym/WorkLocations-v0"
LOCATIONS = ("home", "kitchen", "bedroom")


def _feature_map(obs: dict) -> FeatureMap:
    n = int(obs["map_count"])
    levels = int(round(math.log2(obs["panorama"].shape[1] / obs["map_panorama"].shape[1])))
    return FeatureMap(obs["map_panorama"], obs["map_templates"][:n], obs["map_template_xy"][:n],
                      obs["map_points"][:n], obs["map_pose"].astype(np.float64), levels)


def grid_offsets(radius: float = 0.5, spacing: float = 0.1) -> np.ndarray:
    """Grid points ``(N, 2)`` (m) within ``radius`` of the origin."""
    ticks = np.arange(-radius, radius + 1e-9, spacing)
    xy = np.array([(x, y) for x in ticks for y in ticks])
    return xy[np.hypot(xy[:, 0], xy[:, 1]) <= radius + 1e-9]


def _poses(fmap: FeatureMap, fits, spacing: float, headings: int, random_poses: int,
           rng: np.random.Generator) -> list[np.ndarray]:
    """Poses (x, y, yaw) within 0.5 m of the work location where ``fits(xy)``: a grid
    with ``spacing`` at ``headings`` headings from the taught one, or, with
    ``random_poses`` > 0, that many uniform in the disc with uniform headings."""
    x0, y0, yaw0 = fmap.pose
    if random_poses == 0:
        return [np.array([x0 + dx, y0 + dy, yaw0 + 2 * math.pi * k / headings])
                for dx, dy in grid_offsets(0.5, spacing) if fits((x0 + dx, y0 + dy))
                for k in range(headings)]
    poses = []
    for _ in range(100 * random_poses):
        r, a = 0.5 * math.sqrt(rng.uniform()), rng.uniform(0, 2 * math.pi)
        xy = (x0 + r * math.cos(a), y0 + r * math.sin(a))
        if fits(xy):
            poses.append(np.array([*xy, rng.uniform(0, 2 * math.pi)]))
            if len(poses) == random_poses:
                return poses
    raise ValueError(f"the robot fits at fewer than {random_poses} of {100 * random_poses} "
                     f"random positions within 0.5 m of the work location {tuple(fmap.pose[:2])}")


def localisation_experiment(daily_changes: float, spacing: float, headings: int,
                            seed: int = 0, random_poses: int = 0) -> list[dict]:
    """One row per (location, pose where the robot's body fits; :func:`_poses`): errors
    in cm and degrees."""
    rows = []
    gym.register_envs(homing_gym)
    rng = np.random.default_rng(seed)
    for name in LOCATIONS:
        env = gym.make(ENV_ID, goal_location=name, daily_changes=daily_changes, **MEASURED_WITH)
        obs, _ = env.reset(seed=seed)
        fmap, u = _feature_map(obs), env.unwrapped

        def fits(xy) -> bool:
            return clearance(u.scene, xy) >= u.robot_config.body_radius

        for pose in _poses(fmap, fits, spacing, headings, random_poses, rng):
            t0 = time.process_time()
            pano = u.render_panorama(pose)
            t1 = time.process_time()
            result = localise(pano, fmap)
            t2 = time.process_time()
            row = {"location": name, "offset": [float(pose[0] - fmap.pose[0]),
                                                float(pose[1] - fmap.pose[1])],
                   "heading": float(pose[2]), "found": result.found,
                   "render_s": t1 - t0, "localise_s": t2 - t1, "ok": result.pose is not None}
            if result.pose is not None:
                row["error_cm"] = 100 * math.dist(result.pose[:2], pose[:2])
                row["heading_error_deg"] = math.degrees(
                    abs(math.remainder(result.pose[2] - pose[2], 2 * math.pi)))
            rows.append(row)
        env.close()
    return rows


def _errors_summary(rows: list[dict]) -> dict:
    """Error statistics of ``rows``; the share counts unlocalised poses as failures."""
    ok = [r for r in rows if r["ok"]]
    err = np.array([r["error_cm"] for r in ok])
    head = np.array([r["heading_error_deg"] for r in ok])
    return {"poses": len(rows), "localised": len(ok),
            "error_cm_median": float(np.median(err)), "error_cm_p90": float(np.percentile(err, 90)),
            "heading_deg_median": float(np.median(head)),
            "heading_deg_p90": float(np.percentile(head, 90)),
            "share_within_10cm_and_2deg_of_all": float(np.sum((err < 10) & (head < 2)) / len(rows))}


def summarise_localisation(rows: list[dict]) -> dict:
    """:func:`_errors_summary` of all rows and of each work location's, and the speed."""
    loc_s = float(np.mean([r["localise_s"] for r in rows]))
    all_s = float(np.mean([r["localise_s"] + r["render_s"] for r in rows]))
    by_location = {name: _errors_summary([r for r in rows if r["location"] == name])
                   for name in LOCATIONS if any(r["location"] == name for r in rows)}
    return {**_errors_summary(rows), "by_location": by_location,
            "localisations_per_s": 1 / loc_s, "with_rendering_per_s": 1 / all_s}


def travel_experiment(episodes: int, seed: int, daily_changes: float) -> list[dict]:
    gym.register_envs(homing_gym)
    env = gym.make(ENV_ID, daily_changes=daily_changes, **MEASURED_WITH)
    controller = homing_baselines.make("multires")
    prepare_policy(controller, env)
    rows = []
    for s in range(seed, seed + episodes):
        arrival: list[float] = []

        def localising(t, obs, action, info) -> None:
            if not arrival and controller.phase == LOCALISE:
                arrival.append(info["distance_to_goal"])

        run = rollout(env, controller, s, on_step=localising)
        info = run.info
        rows.append({"seed": s, "path": [info["start_location"], info["goal_location"]],
                     "arrival_cm": 100 * arrival[0] if arrival else None,
                     "final_cm": 100 * info["distance_to_goal"], "success": info["is_success"],
                     "steps": run.steps, "collisions": info["collisions"]})
        print(rows[-1], flush=True)
    env.close()
    return rows


def _cdf(ax, values, label):
    v = np.sort(np.asarray(values))
    ax.step(v, np.arange(1, len(v) + 1) / len(v), where="post", label=label)


def main(argv: list[str] | None = None) -> int:
    parser = command_parser("python -m homing_train.figures.multires", __doc__)
    parser.add_argument("experiment", choices=("localisation", "travel"))
    parser.add_argument("--out", type=output_dir_argument, default="docs/multires")
    parser.add_argument("--spacing", type=float, default=0.2, help="grid spacing (m)")
    parser.add_argument("--headings", type=int, default=4)
    parser.add_argument("--random-poses", type=int, default=0,
                        help="localisation: this many seeded random poses per work location "
                             "(uniform in the 0.5 m disc, any heading) instead of the grid")
    parser.add_argument("--episodes", type=int, default=30)
    parser.add_argument("--seed", type=seed_value, default=0)
    parser.add_argument("--daily-changes", type=float, default=0.0)
    args = parser.parse_args(argv)
    if not (args.spacing > 0 and args.headings >= 1 and args.random_poses >= 0):
        parser.error(f"need --spacing > 0 m, --headings >= 1 and --random-poses >= 0, got "
                     f"{args.spacing}, {args.headings}, {args.random_poses}")
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    if args.experiment == "localisation":
        results = {}
        fig, axes = plt.subplots(1, 2, figsize=(9, 3.5))
        for label, changes in (("as taught", 0.0), ("daily changes 1.0", 1.0)):
            rows = localisation_experiment(changes, args.spacing, args.headings, args.seed,
                                            args.random_poses)
            results[label] = {"summary": summarise_localisation(rows), "rows": rows}
            ok = [r for r in rows if r["ok"]]
            _cdf(axes[0], [r["error_cm"] for r in ok], label)
            _cdf(axes[1], [r["heading_error_deg"] for r in ok], label)
            print(label, results[label]["summary"], flush=True)
        axes[0].set_xscale("log")
        axes[1].set_xscale("log")
        axes[0].axvline(10, color="grey", ls=":")
        axes[1].axvline(2, color="grey", ls=":")
        axes[0].set_xlabel("position error (cm)")
        axes[1].set_xlabel("heading error (deg)")
        axes[0].set_ylabel("share of localised poses")
        axes[0].legend()
        fig.suptitle("Self-localisation within 0.5 m of the work locations (paper: <10 cm, <2 deg)")
        fig.tight_layout()
        save_figure(fig, out / "localisation.png", dpi=110)
        (out / "localisation.json").write_text(json.dumps(results, indent=1))
    else:
        rows = travel_experiment(args.episodes, args.seed, args.daily_changes)
        tag = "" if args.daily_changes == 0 else f"_changes{args.daily_changes:g}"
        summary = {"episodes": len(rows), "success_rate": float(np.mean([r["success"] for r in rows])),
                   "final_cm_median": float(np.median([r["final_cm"] for r in rows])),
                   "arrival_cm_median": float(np.median([r["arrival_cm"] for r in rows
                                                         if r["arrival_cm"] is not None])),
                   "daily_changes": args.daily_changes}
        print(summary)
        (out / f"travel{tag}.json").write_text(json.dumps({"summary": summary, "episodes": rows},
                                                           indent=1))
        fig, ax = plt.subplots(figsize=(5, 3.5))
        _cdf(ax, [r["arrival_cm"] for r in rows if r["arrival_cm"] is not None],
             "after the arrival decision (Fig. 5)")
        _cdf(ax, [r["final_cm"] for r in rows], "final stop (after self-localisation)")
        ax.axvline(10, color="grey", ls=":")
        ax.set_xlabel("distance to the work location (cm)")
        ax.set_ylabel("share of episodes")
        ax.legend(fontsize=8)
        fig.tight_layout()
        save_figure(fig, out / f"travel{tag}.png", dpi=110)
    return 0


if __name__ == "__main__":
    sys.exit(main())
