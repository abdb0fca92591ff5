"""Yu & Kim (2011) evaluation in the ``arena``: Figs. 4-6 and the Eq. 1 distance errors.

Distance estimation (``distance``, :mod:`homing_baselines.distance`) against Franz et al. 1998
warping (``warping``, :mod:`homing_baselines.warping`), both without a compass.

* ``fields``: on a grid over the free floor (spacing ``--grid``, random headings), the
  robot takes the first view, steps ``STEP`` m straight ahead, takes the second, and
  the home direction of the pure function is drawn at the grid point (§III: "placing the
  mobile robot at each grid point and computing the moving direction after driving one
  step movement forward"); warping decides from the first view. The nest map is
  measured as in the paper, from two rendered nest views one step apart. Writes
  ``fig4_vector_maps.png`` (AAE in the titles), ``fig5_angular_error.png`` (angular error
  and homeward component cos against distance from home, means with 95% Student-t
  intervals, ``--samples`` random poses) and ``distance_error.png`` (Eq. 1 error of
  every measured landmark over the grid: median and 90th percentile, %).
* ``success``: Fig. 6, success rate of ``--trials`` closed-loop LocalHoming-v0 episodes
  per start-distance bin to a fixed nest at the arena centre (``HOME_POSE``; starts
  uniform in each bin, random headings; ``FIG6_STEPS`` steps at most), the same tasks for
  both controllers (:func:`fig6_tasks`, :func:`homing_train.harness.evaluate.run_episodes` with a home
  pose per task): ``fig6_success.png`` and ``success.json`` (Wilson 95% intervals).
* ``eval``: the 200-episode LocalHoming-v0 suite of a controller (as ``homing-eval``;
  ``distance`` gets the ``goal_step`` observation, the paper's second nest snapshot).

Command line::

    python -m homing_train.figures.yukim fields --out docs/yu_kim
    python -m homing_train.figures.yukim success --out docs/yu_kim --trials 100 --workers 2
    python -m homing_train.figures.yukim eval --policy distance --episodes 200 --workers 2 \\
        --out results/distance.json
"""

from __future__ import annotations

import json
import math
import os
import sys
from dataclasses import dataclass

import gymnasium as gym
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from scipy import stats  # noqa: E402
from tqdm import tqdm  # noqa: E402

import homing_baselines  # noqa: E402
import homing_gym  # noqa: E402,F401
from homing_baselines.distance import (DistanceConfig, DistanceController,  # noqa: E402
                                       build_nest_map, distance_homing)
from homing_baselines.warping import WarpingController, warping_homing  # noqa: E402
from homing_gym.cli import command_parser, seed_value, worker_count  # noqa: E402
from homing_gym.geometry import wrap_angle  # noqa: E402
from homing_gym.scenes.base import clearance  # noqa: E402
from homing_gym.render.topdown import HOME, MapCanvas, draw_pose, draw_scene  # noqa: E402
from homing_train.harness.metrics import wilson_interval  # noqa: E402
from homing_train.figures import MEASURED_WITH  # noqa: E402
from homing_train.harness.protocols import ring_starts  # noqa: E402
from homing_gym.outputs import (checked_output_dir, checked_output_file,  # noqa: E402
                                save_figure)

ENV_ID = "homing_gym/LocalHoming-v0"
HOME_POSE = (0.0, 0.0, 0.0)  # the nest: arena centre, among the four cylinders
STEP = 0.15  # metres, the controller's default step_length
MARGIN = 0.22  # clearance (m) of grid poses, as the env's start poses
CONTROLLERS = {"distance": DistanceController, "warping": WarpingController}


def register_controllers() -> None:
    """Register ``distance`` and ``warping`` (until ``baselines/__init__.py`` does)."""
    for name, cls in CONTROLLERS.items():
        if name not in homing_baselines.available():
            homing_baselines.register(name, cls)


def mean_ci(values: np.ndarray) -> tuple[float, float]:
    """Mean and half-width of its 95% Student-t interval."""
    v = np.asarray(values, np.float64)
    if v.size < 2:
        return (float(v.mean()) if v.size else math.nan), math.nan
    return float(v.mean()), float(stats.t.ppf(0.975, v.size - 1) * stats.sem(v))


@dataclass
class Sample:
    """One pose: where the decision is drawn (x, y, heading) and the errors (degrees)."""

    x: float
    y: float
    heading: float
    distance: float
    distance_error_deg: float  # NaN: no decision
    warping_error_deg: float
    distance_dir: float  # world direction (radians) or NaN
    warping_dir: float
    distance_all_error_deg: float


class Renderer:
    """Renders panoramas in the arena with the robot body placed under the camera."""

    def __init__(self) -> None:
        self.env = gym.make(ENV_ID, obs_keys=("panorama", "goal"), **MEASURED_WITH)
        self.env.reset(seed=0, options={"home": HOME_POSE, "start": (1.0, 1.0, 0.0)})
        self.scene = self.env.unwrapped.scene

    def __call__(self, pose) -> np.ndarray:
        u = self.env.unwrapped
        u.sim.robot.set_pose(float(pose[0]), float(pose[1]), float(pose[2]))
        return u.render_panorama(np.asarray(pose, dtype=np.float64))

    def close(self) -> None:
        self.env.close()


def ahead(pose, step: float) -> np.ndarray:
    return np.array([pose[0] + step * math.cos(pose[2]), pose[1] + step * math.sin(pose[2]),
                     pose[2]])


def evaluate_pose(render: Renderer, pose, nest, goal) -> tuple[Sample, list]:
    """Both methods' decisions at ``pose``; the Eq. 1 errors (relative) of the landmarks."""
    pose = np.asarray(pose, np.float64)
    second = ahead(pose, STEP)
    v0, v1 = render(pose), render(second)
    true_dir = math.atan2(HOME_POSE[1] - second[1], HOME_POSE[0] - second[0])
    errs = {}
    dirs = {}
    for mode in ("cyclic", "all"):
        _, hd, diag = distance_homing(v0, v1, STEP, nest, 0.0, DistanceConfig(assignments=mode))
        dirs[mode] = math.nan if hd is None else wrap_angle(second[2] + hd)
        errs[mode] = (math.nan if hd is None
                      else abs(math.degrees(wrap_angle(dirs[mode] - true_dir))))
    wd, _, _ = warping_homing(v0, goal)
    w_world = wrap_angle(pose[2] + wd)
    w_true = math.atan2(HOME_POSE[1] - pose[1], HOME_POSE[0] - pose[0])
    # Eq. 1 errors against the nearest true landmark bearing from the second position
    rel = []
    cyl = np.array([lm.position for lm in render.scene.landmarks])
    tb = np.arctan2(cyl[:, 1] - second[1], cyl[:, 0] - second[0]) - second[2]
    tr = np.hypot(cyl[:, 0] - second[0], cyl[:, 1] - second[1])
    for b, r in zip(diag.ego.bearings, diag.ego.distances):
        if np.isfinite(r):
            k = int(np.argmin(np.abs(wrap_angle(tb - b))))
            rel.append((r - tr[k]) / tr[k])
    d = math.hypot(pose[0] - HOME_POSE[0], pose[1] - HOME_POSE[1])
    return Sample(float(pose[0]), float(pose[1]), float(pose[2]), d, errs["cyclic"],
                  abs(math.degrees(wrap_angle(w_world - w_true))), dirs["cyclic"], w_world,
                  errs["all"]), rel


def free_poses(scene, xy: np.ndarray, rng) -> np.ndarray:
    """Keep points with clearance at the pose and one step ahead; random headings."""
    out = []
    for x, y in xy:
        if math.hypot(x - HOME_POSE[0], y - HOME_POSE[1]) < 0.15:
            continue
        for _ in range(20):
            h = rng.uniform(-np.pi, np.pi)
            if (clearance(scene, (x, y)) >= MARGIN
                    and clearance(scene, tuple(ahead((x, y, h), STEP)[:2])) >= MARGIN - 0.05):
                out.append((x, y, h))
                break
    return np.array(out)


def run_fields(out: str, grid: float, samples: int, seed: int) -> dict:
    render = Renderer()
    try:
        nest = build_nest_map(render(HOME_POSE), render(ahead(HOME_POSE, STEP)), STEP)
        goal = render(HOME_POSE)
        rng = np.random.default_rng(seed)
        (xmin, ymin), (xmax, ymax) = render.scene.bounds
        xs = np.arange(xmin + grid / 2, xmax, grid)
        gx, gy = np.meshgrid(xs, np.arange(ymin + grid / 2, ymax, grid))
        grid_poses = free_poses(render.scene, np.column_stack([gx.ravel(), gy.ravel()]), rng)
        rand_xy = rng.uniform([xmin, ymin], [xmax, ymax], size=(samples * 3, 2))
        rand_poses = free_poses(render.scene, rand_xy, rng)[:samples]
        grid_samples, rel = [], []
        for pose in tqdm(grid_poses, desc="grid", unit="pose"):
            s, r = evaluate_pose(render, pose, nest, goal)
            grid_samples.append(s)
            rel += r
        rand_samples = [evaluate_pose(render, p, nest, goal)[0]
                        for p in tqdm(rand_poses, desc="random poses", unit="pose")]
        scene = render.scene
    finally:
        render.close()
    summary = {"nest_map_distances_m": nest.distances.tolist(), "nest_map_status": nest.status}
    summary["fig4"] = plot_fields(scene, grid_samples, grid, os.path.join(out, "fig4_vector_maps.png"))
    summary["fig5"] = plot_errors(rand_samples, os.path.join(out, "fig5_angular_error.png"))
    summary["distance_error"] = plot_distance_error(np.array(rel), os.path.join(out, "distance_error.png"))
    summary["grid_points"] = len(grid_samples)
    summary["random_poses"] = len(rand_samples)
    return summary


def _aae(errors) -> tuple[float, float, int]:
    e = np.asarray(errors, np.float64)
    ok = e[np.isfinite(e)]
    return (float(ok.mean()), float(np.cos(np.radians(ok)).mean()), int((~np.isfinite(e)).sum()))


def plot_fields(scene, samples: list[Sample], grid: float, path: str) -> dict:
    fig, axes = plt.subplots(1, 2, figsize=(10, 5.4), dpi=100)
    canvas = MapCanvas(scene, 480)
    stats = {}
    for ax, name, attr_dir, attr_err in ((axes[0], "distance estimation", "distance_dir",
                                          "distance_error_deg"),
                                         (axes[1], "warping (Franz 1998)", "warping_dir",
                                          "warping_error_deg")):
        import cv2

        img = draw_scene(scene, canvas)
        length = 0.4 * grid
        for s in samples:
            c = getattr(s, attr_dir)
            if math.isnan(c):
                cv2.circle(img, canvas.px(s.x, s.y), 3, (40, 90, 200), -1, cv2.LINE_AA)
                continue
            tail = canvas.px(s.x - length / 2 * math.cos(c), s.y - length / 2 * math.sin(c))
            tip = canvas.px(s.x + length / 2 * math.cos(c), s.y + length / 2 * math.sin(c))
            cv2.arrowedLine(img, tail, tip, (30, 30, 30), 2, cv2.LINE_AA, tipLength=0.35)
        draw_pose(img, canvas, HOME_POSE, 0.16, HOME, filled=False)
        aae, cos, none = _aae([getattr(s, attr_err) for s in samples])
        stats[name] = {"aae_deg": aae, "homeward": cos, "no_decision": none}
        ax.imshow(img)
        ax.axis("off")
        ax.set_title(f"{name}\nAAE {aae:.1f} deg, homeward {cos:.2f}, no decision {none}",
                     fontsize=10)
    aae_all = _aae([s.distance_all_error_deg for s in samples])
    stats["distance estimation, all assignments"] = {
        "aae_deg": aae_all[0], "homeward": aae_all[1], "no_decision": aae_all[2]}
    fig.suptitle("Fig. 4-like vector maps (arena, no compass; blue dots: no decision)")
    fig.tight_layout(rect=(0, 0, 1, 0.95))
    save_figure(fig, path)
    plt.close(fig)
    return stats


def plot_errors(samples: list[Sample], path: str, width: float = 0.2) -> dict:
    d = np.array([s.distance for s in samples])
    edges = np.arange(0.0, d.max() + width, width)
    fig, axes = plt.subplots(1, 2, figsize=(10, 4), dpi=100)
    out = {}
    for name, attr, colour in (("distance estimation", "distance_error_deg", "C0"),
                               ("warping (Franz 1998)", "warping_error_deg", "C3")):
        e = np.array([getattr(s, attr) for s in samples])
        rows = []
        for lo, hi in zip(edges[:-1], edges[1:]):
            sel = (d >= lo) & (d < hi) & np.isfinite(e)
            if sel.sum() < 2:
                continue
            m, h = mean_ci(e[sel])
            c, hc = mean_ci(np.cos(np.radians(e[sel])))
            rows.append({"lo": lo, "hi": hi, "n": int(sel.sum()), "error_deg": m,
                         "error_ci": h, "cos": c, "cos_ci": hc})
        centres = [100 * (r["lo"] + r["hi"]) / 2 for r in rows]
        axes[0].errorbar(centres, [r["error_deg"] for r in rows],
                         yerr=[r["error_ci"] for r in rows], color=colour, capsize=3,
                         marker="o", label=name)
        axes[1].errorbar(centres, [r["cos"] for r in rows], yerr=[r["cos_ci"] for r in rows],
                         color=colour, capsize=3, marker="o", label=name)
        out[name] = rows
    axes[0].set_ylabel("angular error (deg)")
    axes[1].set_ylabel("homeward component cos(error)")
    for ax in axes:
        ax.set_xlabel("distance from home (cm)")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    fig.suptitle("Fig. 5-like: mean with 95% t-intervals, no compass")
    fig.tight_layout()
    save_figure(fig, path)
    plt.close(fig)
    return out


def plot_distance_error(rel: np.ndarray, path: str) -> dict:
    pct = 100 * np.abs(rel)
    stats = {"landmarks": int(pct.size), "median_pct": float(np.median(pct)),
             "p90_pct": float(np.percentile(pct, 90)), "mean_signed_pct": float(100 * rel.mean())}
    fig, ax = plt.subplots(figsize=(5, 3.5), dpi=100)
    ax.hist(np.clip(100 * rel, -100, 100), bins=80, color="C0")
    ax.set_xlabel("Eq. 1 distance error (R - true) / true (%)")
    ax.set_ylabel("landmarks")
    ax.set_title(f"median |error| {stats['median_pct']:.1f}%, 90th pct "
                 f"{stats['p90_pct']:.1f}% (n={pct.size})", fontsize=10)
    fig.tight_layout()
    save_figure(fig, path)
    plt.close(fig)
    return stats


FIG6_BINS = ((0.3, 0.6), (0.6, 0.9), (0.9, 1.2), (1.2, 1.4))
FIG6_STEPS = 300  # 30 s: about twice what distance estimation needs from 1.4 m


def fig6_tasks(trials: int, seed: int, bins=FIG6_BINS) -> list[list[tuple]]:
    """Per bin, ``trials`` tasks (seed, start, home): the nest fixed at ``HOME_POSE`` (as
    the paper's nest), starts at a distance uniform in the bin, uniform direction, random
    heading (§III: "an arbitrary position with random direction of heading"), with the
    env's start clearance (:func:`homing_train.harness.protocols.ring_starts`)."""
    tasks = ring_starts("arena", HOME_POSE, bins, trials, seed, margin=MARGIN)
    return [tasks[b * trials:(b + 1) * trials] for b in range(len(bins))]


def run_success(out: str, trials: int, workers: int, seed: int, bins=FIG6_BINS,
                max_steps: int = FIG6_STEPS) -> dict:
    """Fig. 6: ``trials`` episodes per start-distance bin to the fixed nest, both methods
    on the same tasks (``distance`` with the ``goal_step`` nest snapshot)."""
    from homing_train.harness.evaluate import run_episodes
    from homing_train.harness.policies import policy_spec

    kwargs = {"obs_keys": ["panorama", "goal", "goal_step"], "max_episode_steps": max_steps,
              **MEASURED_WITH}
    tasks = fig6_tasks(trials, seed, bins)
    results = {}
    for name in CONTROLLERS:
        rows = []
        for (lo, hi), bin_tasks in zip(bins, tasks):
            recs = run_episodes(policy_spec(name), ENV_ID, kwargs, bin_tasks, workers,
                                desc=f"{name} [{lo}, {hi}) m")
            ok = np.array([r.success for r in recs], float)
            k, n = int(ok.sum()), len(ok)
            rows.append({"lo": lo, "hi": hi, "trials": n, "successes": k,
                         "success_rate": k / n, "success_ci": list(wilson_interval(k, n)),
                         "collisions_mean": float(np.mean([r.collisions for r in recs])),
                         "final_distance_mean": float(np.mean([r.final_distance for r in recs])),
                         "steps_mean": float(np.mean([r.steps for r in recs]))})
            print(f"{name} [{lo}, {hi}) m: success {k}/{n}", flush=True)
        results[name] = rows
    with open(os.path.join(out, "success.json"), "w") as f:  # before plotting
        json.dump(results, f, indent=1, default=float)
    plot_success(results, trials, max_steps, os.path.join(out, "fig6_success.png"))
    return results


def plot_success(results: dict, trials: int, max_steps: int, path: str) -> None:
    """Fig. 6 from ``results[name] = [{"lo", "hi", "success_rate", "success_ci"}, ...]``."""
    fig, ax = plt.subplots(figsize=(5.5, 4), dpi=100)
    for (name, rows), colour in zip(results.items(), ("C0", "C3")):
        c = [100 * (r["lo"] + r["hi"]) / 2 for r in rows]
        y = [100 * r["success_rate"] for r in rows]
        err = np.clip(np.array([[100 * (r["success_rate"] - r["success_ci"][0]),
                                 100 * (r["success_ci"][1] - r["success_rate"])]
                                for r in rows]).T, 0, None)  # Wilson at k = n: -1e-16
        ax.errorbar(c, y, yerr=err, marker="o", capsize=3, color=colour, label=name)
    ax.set_xlabel("start distance from home (cm)")
    ax.set_ylabel(f"success rate (%) of {trials} trials per bin")
    ax.set_ylim(0, 105)
    ax.grid(alpha=0.3)
    ax.legend()
    ax.set_title(f"Fig. 6-like: fixed nest at the arena centre, no compass\n"
                 f"({max_steps} steps max; 95% Wilson intervals)", fontsize=10)
    fig.tight_layout()
    save_figure(fig, path)
    plt.close(fig)


def main(argv: list[str] | None = None) -> int:
    parser = command_parser("python -m homing_train.figures.yukim", __doc__)
    parser.add_argument("what", choices=("fields", "success", "eval"))
    parser.add_argument("--out", default="docs/yu_kim", help="output folder (eval: JSON path)")
    parser.add_argument("--grid", type=float, default=0.2, help="vector-map spacing (m)")
    parser.add_argument("--samples", type=int, default=600, help="random poses for Fig. 5")
    parser.add_argument("--trials", type=int, default=100, help="episodes per distance bin")
    parser.add_argument("--episodes", type=int, default=200)
    parser.add_argument("--policy", choices=tuple(CONTROLLERS), default="distance")
    parser.add_argument("--workers", type=worker_count, default=2)
    parser.add_argument("--seed", type=seed_value, default=0)
    args = parser.parse_args(argv)
    try:                        # before any work: eval writes a JSON file, the others a folder
        (checked_output_file if args.what == "eval" else checked_output_dir)(args.out)
    except ValueError as err:
        parser.error(str(err))
    register_controllers()
    if args.what == "eval":
        from homing_train.harness.evaluate import evaluate, format_summary

        kwargs = ({"obs_keys": ["panorama", "goal", "goal_step"]} if args.policy == "distance"
                  else {}) | MEASURED_WITH
        result = evaluate(args.policy, ENV_ID, args.episodes, args.seed, kwargs,
                          workers=args.workers)
        result.save(args.out)
        print(format_summary(result))
        return 0
    os.makedirs(args.out, exist_ok=True)
    if args.what == "fields":
        summary = run_fields(args.out, args.grid, args.samples, args.seed)
        name = "fields.json"
    else:
        summary = run_success(args.out, args.trials, args.workers, args.seed)
        name = "success.json"
    with open(os.path.join(args.out, name), "w") as f:
        json.dump(summary, f, indent=1, default=float)
    print(json.dumps({k: v for k, v in summary.items() if k != "fig5"}, indent=1, default=float))
    return 0


if __name__ == "__main__":
    sys.exit(main())
