"""Issue 4 experiments for Hong et al. 1991 (``snapshot``) and, when registered, Franz et
al. 1998 (``warping``): homing vector fields, LocalHoming-v0 suites, RouteFollowing-v0
routes with and without an illumination change, and the sweep of the paper-open constants.

    python -m homing_train.figures.hong --out docs/hong            # everything
    python -m homing_train.figures.hong --out docs/hong --only sweep field eval route

Writes PNG/JSON files and ``results.json`` under ``--out``; prints Markdown tables.
Sizes are the issue's: 200 LocalHoming episodes per setting, 20 routes per setting.
"""

from __future__ import annotations

import dataclasses
import json
import math
import os
import sys
from dataclasses import dataclass
from typing import Any

import gymnasium as gym
import numpy as np
from tqdm import tqdm

import homing_baselines
import homing_gym
from homing_baselines.snapshot import HongConfig, hong_homing
from homing_gym.cli import command_parser
from homing_gym.geometry import bearing_to, wrap_angle
from homing_gym.scenes.base import clearance
from homing_train.harness.evaluate import evaluate
from homing_train.figures import MEASURED_WITH
from homing_train.harness.rollout import prepare_policy, rollout
from homing_train.harness.field import homing_field, plot_field
from homing_train.harness.policies import policy_spec
from homing_gym.outputs import output_dir_argument, save_figure

PANORAMA = (60, 360)   # 1 deg per column, Hong's sampling interval
LOCAL = "homing_gym/LocalHoming-v0"
ROUTE = "homing_gym/RouteFollowing-v0"
PER_METHOD = ("field", "eval", "route")   # results keyed "method/setting": a run adds its own
SWEEP: list[tuple[str, dict[str, Any]]] = [
    ("defaults", {}),
    ("k_back = 8 (paper)", {"k_back": 8.0}),
    ("k_back = 20", {"k_back": 20.0}),
    ("target stats at i+psi (literal §3)", {"target_stats": "centre"}),
    ("k_low = 0.05", {"k_low": 0.05}),
    ("k_low = 1.0", {"k_low": 1.0}),
    ("no reshaping (k_low = 1e6)", {"k_low": 1e6}),
    ("k_high = 10", {"k_high": 10.0}),
    ("min_instant, min_total = 0.01, 0.04", {"min_instant": 0.01, "min_total": 0.04}),
    ("min_instant, min_total = 0.05, 0.15", {"min_instant": 0.05, "min_total": 0.15}),
]


def methods() -> list[str]:
    """The methods of issue 4: ``snapshot`` and ``warping``."""
    return ["snapshot", "warping"]


@dataclass
class PairSet:
    """Rendered (current, target) panoramas ``distance`` m apart with a common heading
    (Hong's body does not rotate), the true home bearing (radians, robot frame)."""

    scene: str
    distance: float
    current: list[np.ndarray]
    target: list[np.ndarray]
    truth: list[float]


def render_pairs(scene: str, distance: float, n: int, seed: int = 0) -> PairSet:
    """``n`` random pairs with at least 0.25 m clearance in ``scene``."""
    env = gym.make(LOCAL, scene=scene, panorama_shape=PANORAMA, **MEASURED_WITH)
    try:
        env.reset(seed=seed)
        u = env.unwrapped
        rng = np.random.default_rng(seed)
        (x0, y0), (x1, y1) = u.scene.bounds
        out = PairSet(scene, distance, [], [], [])
        while len(out.truth) < n:
            yaw = rng.uniform(-np.pi, np.pi)
            home = np.array([rng.uniform(x0, x1), rng.uniform(y0, y1), yaw])
            a = rng.uniform(-np.pi, np.pi)
            cur = home + [distance * math.cos(a), distance * math.sin(a), 0.0]
            if min(clearance(u.scene, home[:2]), clearance(u.scene, cur[:2])) < 0.25:
                continue
            for pose, store in ((home, out.target), (cur, out.current)):
                u.sim.robot.set_pose(*pose)
                store.append(u.render_panorama(pose))
            out.truth.append(bearing_to(cur, home[:2]))
        return out
    finally:
        env.close()


def direction_errors(pairs: PairSet, config: HongConfig, psi_prior: float | None = 0.0
                     ) -> np.ndarray:
    """Absolute errors (degrees) of :func:`hong_homing` on ``pairs``."""
    return np.array([abs(math.degrees(wrap_angle(
        hong_homing(c, t, config, psi_prior=psi_prior).direction - truth)))
        for c, t, truth in zip(pairs.current, pairs.target, pairs.truth)])


def run_sweep(n_pairs: int = 30) -> list[dict[str, Any]]:
    """Effect of the paper-open constants on the direction error of rendered pairs
    (common heading, deviation searched +-10 deg about 0)."""
    sets = [render_pairs(s, d, n_pairs) for s in ("arena", "hallway") for d in (0.15, 0.3)]
    rows = []
    for label, change in tqdm(SWEEP, desc="sweep"):
        cfg = dataclasses.replace(HongConfig(k_psi=10.0), **change)
        row: dict[str, Any] = {"setting": label}
        for ps in sets:
            err = direction_errors(ps, cfg)
            row[f"{ps.scene} {ps.distance} m"] = [float(err.mean()), float(np.mean(err < 30))]
        rows.append(row)
    return rows


def plot_signature(out: str, seed: int = 3) -> dict[str, Any]:
    """Hong's Fig. 3 for the ``hallway``: the signature from the panorama and from the omni
    ring image, with the 15 characteristic points."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from homing_baselines.signature import characteristic_points, signature_from_omni, \
        signature_from_panorama

    env = gym.make(LOCAL, scene="hallway", panorama_shape=PANORAMA, omni_size=256, **MEASURED_WITH,
                   obs_keys=("panorama", "omni"))
    obs, _ = env.reset(seed=seed)
    env.close()
    a, b = signature_from_panorama(obs["panorama"]), signature_from_omni(obs["omni"])
    cp = characteristic_points(a)
    fig, (ax0, ax1) = plt.subplots(1, 2, figsize=(11, 3.4), dpi=100,
                                   gridspec_kw={"width_ratios": [1, 3]})
    ax0.imshow(obs["omni"])
    ax0.set_title("omni ring image (heading up)", fontsize=9)
    ax0.axis("off")
    deg = np.arange(360) + 0.5
    ax1.plot(deg, a, label="from the panorama rows", lw=1.2)
    ax1.plot(deg, b, label="from the omni horizon circle", lw=1, ls="--")
    ax1.plot(np.degrees(cp.bearing), a[cp.index], "o", ms=5, mfc="none", color="k",
             label="characteristic points")
    ax1.set_xlabel("bearing (deg, counter-clockwise from heading)")
    ax1.set_ylabel("luminance")
    ax1.set_xlim(0, 360)
    ax1.legend(fontsize=8)
    fig.tight_layout()
    save_figure(fig, os.path.join(out, "signature.png"))
    plt.close(fig)
    return {"correlation": float(np.corrcoef(a, b)[0, 1]),
            "mean_abs_difference": float(np.abs(a - b).mean()),
            "potential_points": cp.n_potential}


def run_fields(out: str, names: list[str], seed: int = 0) -> dict[str, Any]:
    """Vector fields (AAE, return ratio) in ``arena`` and ``hallway``."""
    res = {}
    for name in names:
        for scene in ("arena", "hallway"):
            kw = {"scene": scene, "panorama_shape": PANORAMA, "success_on": "stop",
                  **MEASURED_WITH}
            field = homing_field(policy_spec(name), LOCAL, grid=0.2 if scene == "arena" else 0.3,
                                 seed=seed, env_kwargs=kw)
            path = os.path.join(out, f"field_{name}_{scene}.png")
            plot_field(field, path)
            res[f"{name}/{scene}"] = {"aae_deg": field.aae_deg, "homeward": field.homeward,
                                      "return_ratio": field.return_ratio,
                                      "points": len(field.points), "plot": os.path.basename(path)}
    return res


def run_eval(names: list[str], episodes: int = 200) -> dict[str, Any]:
    """LocalHoming-v0 suites: default start distances and (1.5, 2.5) m where it fits."""
    res = {}
    for name in names:
        for label, extra in (("default", {}), ("far", {"start_distance": (1.5, 2.5)})):
            kw = {"panorama_shape": PANORAMA, "success_on": "stop", **MEASURED_WITH, **extra}
            try:
                r = evaluate(name, LOCAL, episodes=episodes, seed=0, env_kwargs=kw)
            except ValueError as err:      # a start distance that cannot fit the arena
                res[f"{name}/{label}"] = {"error": str(err)}
                continue
            s = r.summary
            res[f"{name}/{label}"] = {k: s[k] for k in (
                "success_rate", "success_ci", "spl", "final_distance_mean",
                "final_distance_cm_median", "collisions_mean")}
    return res


def run_routes(names: list[str], episodes: int = 20, drive: str = "differential",
               first_seed: int = 0) -> dict[str, Any]:
    """RouteFollowing-v0, ``success_on="stop"``: share of routes with all 17 targets
    reached (every stop within the 0.1 m radius) and mean per-target error; with
    ``drive="synchro"`` on Hong's robot, which translates without turning (keys end in
    ``/synchro``): it is put at the route's heading (``start_jitter`` 5 cm, 0 rad), since
    a body that never turns could never correct a start heading error, and the paper's
    robot took its snapshots and ran with one heading. Routes use the env seeds
    ``first_seed``, ``first_seed + 1``, ...; keys of a ``first_seed`` other than 0 end
    in ``/seeds=FIRST-LAST``."""
    res = {}
    for name in names:
        for light in (0.0, 0.5):
            kw = {"panorama_shape": PANORAMA, "success_on": "stop", **MEASURED_WITH,
                  "lighting_change": light,
                  "drive": drive}
            if drive == "synchro":
                kw["start_jitter"] = (0.05, 0.0)
            env = gym.make(ROUTE, **kw)
            radius = env.unwrapped.task.success_radius
            policy = policy_spec(name).build()
            prepare_policy(policy, env)
            all_ok, errors, n_done, last_ok = [], [], [], []
            seeds = range(first_seed, first_seed + episodes)
            for seed in tqdm(seeds, desc=f"{name} route light={light}"):
                info = rollout(env, policy, seed).info
                errs = list(info["target_errors"])      # read by the harness only
                errors.extend(errs)
                n_done.append(len(errs))
                all_ok.append(len(errs) == 17 and max(errs) < radius)
                last_ok.append(bool(info["is_success"]))
            env.close()
            key = f"{name}/lighting={light}" + ("/synchro" if drive == "synchro" else "")
            if first_seed:
                key += f"/seeds={seeds[0]}-{seeds[-1]}"
            res[key] = {
                "all_17_within_radius": float(np.mean(all_ok)),
                "episode_success": float(np.mean(last_ok)),
                "mean_target_error_m": float(np.mean(errors)) if errors else None,
                "median_target_error_m": float(np.median(errors)) if errors else None,
                "targets_finished_mean": float(np.mean(n_done))}
    return res


def markdown_tables(results: dict[str, Any]) -> str:
    """The Markdown tables of ``docs/hong.md`` from ``results.json``."""
    out = []
    if "sweep" in results:
        cols = [k for k in results["sweep"][0] if k != "setting"]
        out += ["| setting | " + " | ".join(cols) + " |", "|---" * (len(cols) + 1) + "|"]
        out += ["| " + row["setting"] + " | " + " | ".join(
            f"{row[c][0]:.1f} / {100 * row[c][1]:.0f}%" for c in cols) + " |"
            for row in results["sweep"]]
        out.append("")
    if "field" in results:
        out += ["| method / scene | grid points | AAE (deg) | homeward | return ratio |",
                "|---|---|---|---|---|"]
        out += [f"| {k} | {v['points']} | {v['aae_deg']:.1f} | {v['homeward']:.2f} | "
                f"{100 * v['return_ratio']:.0f}% |" for k, v in results["field"].items()]
        out.append("")
    if "eval" in results:
        out += ["| method / start distance | success [95% CI] | SPL | final error mean "
                "(median) | collisions/episode |", "|---|---|---|---|---|"]
        for k, v in results["eval"].items():
            if "error" in v:
                out.append(f"| {k} | {v['error']} | | | |")
                continue
            lo, hi = v["success_ci"]
            out.append(f"| {k} | {100 * v['success_rate']:.1f}% [{100 * lo:.1f}, "
                       f"{100 * hi:.1f}] | {v['spl']:.3f} | "
                       f"{100 * v['final_distance_mean']:.1f} cm "
                       f"({v['final_distance_cm_median']:.1f}) | {v['collisions_mean']:.2f} |")
        out.append("")
    if "route" in results:
        out += ["| method / lighting_change | all 17 within 0.1 m | last target (env success) "
                "| mean (median) per-target error | targets finished |",
                "|---|---|---|---|---|"]
        out += [f"| {k} | {100 * v['all_17_within_radius']:.0f}% | "
                f"{100 * v['episode_success']:.0f}% | {100 * v['mean_target_error_m']:.1f} cm "
                f"({100 * v['median_target_error_m']:.1f}) | {v['targets_finished_mean']:.1f} |"
                for k, v in results["route"].items()]
    return "\n".join(out)


def main(argv: list[str] | None = None) -> int:
    parser = command_parser("python -m homing_train.figures.hong", __doc__)
    parser.add_argument("--out", type=output_dir_argument, default="docs/hong")
    parser.add_argument("--only", nargs="+", default=["sweep", "field", "eval", "route"],
                        choices=["signature", "sweep", "field", "eval", "route"])
    parser.add_argument("--episodes", type=int, default=200)
    parser.add_argument("--methods", nargs="+", default=None,
                        help="controllers to run (default: snapshot and warping if registered)")
    parser.add_argument("--tables", action="store_true",
                        help="only print the Markdown tables of an existing results.json")
    parser.add_argument("--routes", type=int, default=20)
    parser.add_argument("--drive", choices=["differential", "synchro"], default="differential",
                        help="the robot of the route runs (synchro: Hong's, never turns)")
    parser.add_argument("--route-seed", type=int, default=0,
                        help="the first env seed of the routes (default 0)")
    args = parser.parse_args(argv)
    gym.register_envs(homing_gym)
    os.makedirs(args.out, exist_ok=True)
    path = os.path.join(args.out, "results.json")
    results: dict[str, Any] = json.load(open(path)) if os.path.exists(path) else {}
    if args.tables:
        print(markdown_tables(results))
        return 0
    names = methods() if args.methods is None else args.methods
    unknown = sorted(set(names) - set(homing_baselines.available()))
    if unknown:
        parser.exit(2, f"hong-figures: unknown controllers {unknown}; "
                       f"available: {homing_baselines.available()}\n")
    print(f"methods: {names}")
    steps = {"signature": lambda: plot_signature(args.out), "sweep": lambda: run_sweep(), "field": lambda: run_fields(args.out, names),
             "eval": lambda: run_eval(names, args.episodes),
             "route": lambda: run_routes(names, args.routes, args.drive, args.route_seed)}
    for key in args.only:
        value = steps[key]()
        if key in PER_METHOD and isinstance(results.get(key), dict):
            results[key].update(value)      # keep the other methods' entries
        else:
            results[key] = value
        with open(path, "w") as f:
            json.dump(results, f, indent=1, default=float)
        print(key, json.dumps(results[key], indent=1, default=float))
    return 0


if __name__ == "__main__":
    sys.exit(main())
