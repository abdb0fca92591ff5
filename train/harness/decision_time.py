"""Decision time of the scripted controllers: how long one ``decide()`` takes, each
method on the same observations in the same run, against ``warping`` as the reference.

``python -m homing_train.harness.decision_time [--methods M ...] [--worlds N] [--calls K]``

The observations come from RouteFollowing-v0 with random routes in ``random_nature``
(48 x 256 panoramas by default, the teaching views along): ``--worlds`` worlds, in each
the start and ``--calls`` views after random moves. Every method first decides, untimed,
on the first view of the world where it moves rather than stops (reading its goal,
learning the route's views where it learns them); each timed call on another view of the
world starts from a copy of that state, so it is one steady-state decision that does the
method's work (a stopped controller would return at once). Printed: the median and 90th
percentile in milliseconds, and the median's ratio to ``warping``'s.
"""

from __future__ import annotations

import copy
import json
import time
from dataclasses import asdict, dataclass
from typing import Sequence

import gymnasium as gym
import numpy as np

import homing_baselines
import homing_gym  # noqa: F401  (registers the env ids)
from homing_gym.cli import command_parser, worker_count
from homing_gym.outputs import output_file_argument, write_text_atomic
from homing_train.harness.rollout import prepare_policy

#: The reference every other method's median is divided by.
REFERENCE = "warping"
#: The methods timed by default: every pixel-only method that follows a route or homes.
DEFAULT_METHODS = ("warping", "min-warping", "snapshot", "did", "alv", "perfect-memory",
                   "infomax")


@dataclass(frozen=True)
class DecisionTime:
    """One method's decision times in milliseconds: ``median`` and ``p90`` over
    ``calls`` calls, ``ratio``: the median over the reference's median (same run)."""

    method: str
    calls: int
    median: float
    p90: float
    ratio: float


def _observations(env: gym.Env, worlds: int, calls: int, seed: int) -> list[list[dict]]:
    """Per world: its start observation, then ``calls`` observations after random moves
    (copies: the env reuses no buffer we keep)."""
    rng = np.random.default_rng(seed)
    per_world = []
    for w in range(worlds):
        obs, _ = env.reset(seed=seed + w)
        views = [copy.deepcopy(obs)]
        while len(views) <= calls:
            obs, _, terminated, truncated, _ = env.step(rng.uniform(-1, 1, 2).astype(np.float32))
            if terminated or truncated:
                obs, _ = env.reset(seed=seed + w)
            views.append(copy.deepcopy(obs))
        per_world.append(views)
    return per_world


def _moves(controller, obs: dict, seed: int) -> bool:
    """Reset ``controller`` and let it decide on ``obs`` (reading the goal and learning
    the route where it does): whether it moved, i.e. it has not stopped and its next
    decision does the method's work."""
    controller.reset(seed)
    return controller.decide(obs) is not None


def decision_times(methods: Sequence[str], worlds: int = 10, calls: int = 20,
                   panorama_shape: tuple[int, int] = (48, 256), seed: int = 0
                   ) -> list[DecisionTime]:
    """Time ``decide()`` of each of ``methods`` (module doc); ``ValueError`` for an
    unknown method or a bad count."""
    unknown = [m for m in methods if m not in homing_baselines.available()]
    if unknown:
        raise ValueError(f"unknown methods {unknown}; allowed: {homing_baselines.available()}")
    for name, value in (("worlds", worlds), ("calls", calls)):
        if not (isinstance(value, int) and value >= 1):
            raise ValueError(f"{name} must be an integer >= 1, got {value!r}")
    names = list(dict.fromkeys([REFERENCE, *methods]))
    controllers = {m: homing_baselines.make(m) for m in names}
    keys = {"panorama", "goal"} | {k for c in controllers.values()
                                   for k in c.observation_keys()}
    env = gym.make("homing_gym/RouteFollowing-v0", scene="random_nature", route="random",
                   panorama_shape=tuple(panorama_shape), obs_keys=tuple(sorted(keys)))
    try:
        views = _observations(env, worlds, calls, seed)
        for controller in controllers.values():
            prepare_policy(controller, env)
    finally:
        env.close()
    times: dict[str, list[float]] = {m: [] for m in names}
    for world in views:
        for name, controller in controllers.items():
            warm = next((k for k, obs in enumerate(world) if _moves(controller, obs, seed)),
                        None)
            if warm is None:
                continue                                 # it stops on every view here
            for obs in world[:warm] + world[warm + 1:]:
                fresh = copy.deepcopy(controller)
                start = time.perf_counter()
                fresh.decide(obs)
                times[name].append(1000 * (time.perf_counter() - start))
    if not times[REFERENCE]:
        raise ValueError(f"{REFERENCE} stopped on every view of {worlds} worlds: nothing "
                         f"to compare with; use more worlds")
    reference = float(np.median(times[REFERENCE]))
    return [DecisionTime(m, len(t), float(np.median(t)), float(np.percentile(t, 90)),
                         float(np.median(t)) / reference) for m, t in times.items()]


def times_table(rows: Sequence[DecisionTime]) -> str:
    """A markdown table of the decision times."""
    lines = ["| method | calls | median ms | 90th percentile ms | median / warping's |",
             "|---|---:|---:|---:|---:|"]
    lines += [f"| {r.method} | {r.calls} | {r.median:.2f} | {r.p90:.2f} | {r.ratio:.2f} |"
              for r in rows]
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    parser = command_parser("python -m homing_train.harness.decision_time", __doc__)
    parser.add_argument("--methods", nargs="+", default=list(DEFAULT_METHODS),
                        choices=homing_baselines.available(), metavar="METHOD",
                        help=f"controllers to time beside {REFERENCE}")
    parser.add_argument("--worlds", type=worker_count, default=10,
                        help="random_nature worlds the views come from")
    parser.add_argument("--calls", type=worker_count, default=20,
                        help="timed decisions per world and method")
    parser.add_argument("--shape", type=worker_count, nargs=2, default=[48, 256],
                        metavar=("H", "W"), help="panorama height and width (pixels)")
    parser.add_argument("--json", type=output_file_argument, help="also write the rows here")
    args = parser.parse_args(argv)
    rows = decision_times(args.methods, args.worlds, args.calls, tuple(args.shape))
    print(times_table(rows))
    if args.json:
        write_text_atomic(args.json, json.dumps([asdict(r) for r in rows], indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
