"""``homing-suite``: the package's main job, the comparison of every method on one suite.

    homing-suite                       # 20 episodes of LocalHoming-v0, seed 0, into results/
    homing-suite --episodes 200 --workers 2 --out results/full

Evaluates every registered scripted controller made for the env (:func:`suite_methods`)
and every shipped PPO policy trained on it (``train/shipped/*.zip`` with the evaluation
settings of its ``*.yml``: ``eval_env_kwargs``, ``eval_params``) with the same harness
on the same seeded episodes (episode ``i`` uses seed ``seed + i``), writes one
``<method>.json``/``.csv`` per method into ``--out``, then runs ``homing-compare`` on them:
``table.md`` (printed), ``success_vs_distance.png``, ``final_distance.png`` and
``trajectories.png``.
"""

from __future__ import annotations

import sys
from dataclasses import dataclass
from importlib import resources
from pathlib import Path

import gymnasium as gym
import homing_baselines
import homing_gym  # noqa: F401  (registers the env ids)
from homing_gym.cli import command_parser
from homing_train.extras import missing_extra
from homing_train.harness.compare import compare
from homing_train.harness.evaluate import DEFAULT_ENV, evaluate, format_summary
from homing_train.harness.policies import recorded_settings

POLICY_DIR = Path(str(resources.files("homing_train") / "shipped"))


@dataclass(frozen=True)
class ShippedPolicy:
    """A shipped model and how it is evaluated (from the ``.yml`` beside it)."""

    path: Path
    env_kwargs: dict
    params: dict    # SB3 policy parameters, e.g. {"deterministic": False}
    env_id: str | None = None   # the env it was trained on (None: any)


def shipped_policies(folder: Path = POLICY_DIR) -> dict[str, ShippedPolicy]:
    """Shipped PPO policies by name, with their recorded evaluation settings
    (:func:`homing_train.harness.policies.recorded_settings`)."""
    found = {}
    for model in sorted(folder.glob("*.zip")):
        settings = recorded_settings(str(model))
        found[model.stem] = ShippedPolicy(model, settings.env_kwargs, settings.params,
                                          settings.env_id)
    return found


def suite_methods(env_id: str) -> list[str]:
    """The registered controllers made for ``env_id`` in its default scene
    (:meth:`baselines.Controller.made_for`): e.g. ``multires`` only on WorkLocations-v0,
    the colour-identity bearing laws only where the default scene is ``lab``."""
    env = gym.make(env_id)
    scene = env.unwrapped.scene.name
    env.close()
    return [name for name in homing_baselines.available()
            if homing_baselines.controller_class(name).made_for(env_id, scene)]


def run_suite(out: Path, env_id: str = DEFAULT_ENV, episodes: int = 20, seed: int = 0,
              workers: int = 2, methods: list[str] | None = None) -> dict[str, str]:
    """Evaluate the methods (default: all controllers and shipped policies) and compare."""
    out.mkdir(parents=True, exist_ok=True)
    policies = {name: p for name, p in shipped_policies().items()
                if p.env_id in (None, env_id)}
    if policies and (hint := missing_extra("train")):
        print(f"homing-suite: the learned rows {sorted(policies)} are left out ({hint})")
        policies = {}
    made_for = suite_methods(env_id)
    candidates = homing_baselines.available() + sorted(policies)
    chosen = methods or made_for + sorted(policies)
    unknown = sorted(set(chosen) - set(candidates))
    if unknown:
        raise ValueError(f"unknown methods {unknown}; available: {candidates}")
    paths = []
    for name in chosen:
        shipped = policies.get(name)
        policy, kwargs, params = (str(shipped.path), shipped.env_kwargs, shipped.params) \
            if shipped else (name, {}, {})
        result = evaluate(policy, env_id, episodes=episodes, seed=seed, env_kwargs=kwargs,
                          workers=workers, params=params)
        print(format_summary(result))
        path = out / f"{name}.json"
        result.save(str(path))
        paths.append(str(path))
    return compare(paths, str(out))


def main(argv: list[str] | None = None) -> int:
    parser = command_parser("homing-suite", __doc__)
    parser.add_argument("--env", default=DEFAULT_ENV, help="env id of the suite")
    parser.add_argument("--episodes", type=int, default=20, help="episodes per method")
    parser.add_argument("--seed", type=int, default=0, help="seed of the first episode")
    parser.add_argument("--workers", type=int, default=2, help="parallel processes")
    parser.add_argument("--methods", nargs="+", help="subset of methods (default: all)")
    parser.add_argument("--out", default="results", help="output folder (default: results)")
    args = parser.parse_args(argv)
    if args.episodes < 1 or args.workers < 1:
        parser.error("--episodes and --workers must be >= 1")
    try:
        written = run_suite(Path(args.out), args.env, args.episodes, args.seed, args.workers,
                            args.methods)
    except ValueError as err:
        parser.exit(2, f"homing-suite: error: {err}\n")
    print(Path(written["table"]).read_text())
    print("wrote " + ", ".join(written.values()))
    return 0


if __name__ == "__main__":
    sys.exit(main())
