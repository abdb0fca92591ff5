"""RLlib PPO (new API stack) on the homing envs: training spread over a Ray cluster.

An example and a command: ``python -m homing_train.learning.rllib_ppo --address auto``
trains on the cluster that ``ray start`` made, ``--env-runners N`` envs sampling in
parallel. Needs ``ray[rllib]`` and torch (``pip install "homing-gym[rllib]"``), which pin
their own gymnasium: see docs/training.md, "Scaling out with RLlib".

RLlib's default model catalog has no encoder for ``Dict`` observations, so
:class:`StackedGoalPanorama` stacks the current and the goal panorama as channels (the
early fusion of :mod:`homing_train.learning.extractor`) into one ``(H, W, 6)`` float Box
in [0, 1], which the catalog encodes with its CNN (zero padding: RLlib's default CNN has
no circular padding along azimuth). The PPO hyperparameters are those of ``homing-train``
(``train/learning/hyperparams/ppo.yml``), renamed to RLlib's arguments.
"""

from __future__ import annotations

import json
import math
import os
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import gymnasium as gym
import numpy as np

from homing_gym.cli import IMPORT_VARIABLE, command_parser, seed_value
from homing_train.learning.train import load_hyperparams

if TYPE_CHECKING:
    from ray.rllib.algorithms.ppo import PPOConfig

#: The name RLlib knows :func:`make_env` by (``tune.register_env``).
RLLIB_ENV = "homing_gym_stacked"
#: The observation keys :class:`StackedGoalPanorama` stacks, in channel order.
STACKED_KEYS = ("panorama", "goal")
#: ``ppo.yml`` key -> RLlib ``PPOConfig.training`` argument.
RLLIB_NAMES = {"batch_size": "minibatch_size", "n_epochs": "num_epochs",
               "learning_rate": "lr", "gamma": "gamma", "gae_lambda": "lambda_",
               "clip_range": "clip_param", "ent_coef": "entropy_coeff",
               "vf_coef": "vf_loss_coeff", "max_grad_norm": "grad_clip"}
#: RLlib ``conv_filters`` ([channels, [kernel, kernel], stride]): the layers of
#: ``PanoramaGoalExtractor`` (a 4 x 4 stride-4 patch layer, two 3 x 3 stride-2 layers).
CONV_FILTERS = [[32, [4, 4], 4], [64, [3, 3], 2], [64, [3, 3], 2]]


class StackedGoalPanorama(gym.ObservationWrapper):
    """The ``panorama`` and ``goal`` images (uint8, H x W x 3) as one float32
    H x W x 6 array in [0, 1], panorama channels first: an image RLlib's CNN reads."""

    def __init__(self, env: gym.Env):
        super().__init__(env)
        space = env.observation_space
        keys = set(space.spaces) if isinstance(space, gym.spaces.Dict) else None
        if keys != set(STACKED_KEYS):
            raise ValueError(f"StackedGoalPanorama needs observations with exactly the keys "
                             f"{list(STACKED_KEYS)}, got {space}")
        shapes = {space[k].shape for k in STACKED_KEYS}
        if len(shapes) != 1:
            raise ValueError(f"panorama and goal must have one shape, got {sorted(shapes)}")
        height, width, channels = shapes.pop()
        self.observation_space = gym.spaces.Box(0.0, 1.0, (height, width, 2 * channels),
                                                np.float32)

    def observation(self, observation: dict[str, np.ndarray]) -> np.ndarray:
        stacked = np.concatenate([observation[k] for k in STACKED_KEYS], axis=-1)
        return stacked.astype(np.float32) / np.float32(255)


def make_env(env_config: dict[str, Any]) -> gym.Env:
    """RLlib's env creator, run inside every env runner: ``env_config`` holds ``env_id``
    and the ``gym.make`` keyword arguments."""
    import homing_gym  # registers the env ids in this env runner's process

    kwargs = dict(env_config)
    env_id = kwargs.pop("env_id")
    gym.register_envs(homing_gym)
    return StackedGoalPanorama(gym.make(env_id, **kwargs))


@dataclass
class RllibSettings:
    """One RLlib PPO setup. ``env_kwargs`` (``gym.make`` arguments, e.g.
    ``max_episode_steps``) update those of ``ppo.yml``; ``train_batch_size``: env steps
    per iteration and learner (``None``: ``n_steps x n_envs`` of ``ppo.yml``);
    ``hyperparams``: ``ppo.yml`` keys overriding the file's."""

    env_id: str = "homing_gym/LocalHoming-v0"
    env_kwargs: dict[str, Any] = field(default_factory=dict)
    num_env_runners: int = 2
    num_envs_per_env_runner: int = 1
    train_batch_size: int | None = None
    hyperparams: dict[str, Any] = field(default_factory=dict)
    seed: int = 0

    def __post_init__(self):
        for name, least in (("num_env_runners", 0), ("num_envs_per_env_runner", 1)):
            value = getattr(self, name)
            if not isinstance(value, int) or value < least:
                raise ValueError(f"{name} must be an integer >= {least}, got {value!r}")
        if self.train_batch_size is not None and (not isinstance(self.train_batch_size, int)
                                                  or self.train_batch_size < 2):
            raise ValueError(f"train_batch_size must be an integer >= 2 or None, got "
                             f"{self.train_batch_size!r}")
        unknown = set(self.hyperparams) - set(RLLIB_NAMES) - {"n_steps", "n_envs"}
        if unknown:
            raise ValueError(f"hyperparams {sorted(unknown)} have no RLlib counterpart here; "
                             f"allowed: {sorted(RLLIB_NAMES) + ['n_envs', 'n_steps']}")


def ppo_config(settings: RllibSettings) -> PPOConfig:
    """The ``PPOConfig`` of ``settings``: ``ppo.yml``'s values for ``settings.env_id``
    under RLlib's names, no KL penalty and no value-loss clipping (as stable-baselines3's
    PPO with ``clip_range_vf=None``), the CNN of :data:`CONV_FILTERS` shared by policy and
    value heads of 256 units."""
    from ray.rllib.algorithms.ppo import PPOConfig
    from ray.rllib.core.rl_module.default_model_config import DefaultModelConfig
    from ray.tune import register_env

    table = {**load_hyperparams(settings.env_id), **settings.hyperparams}
    training = {}
    for key, name in RLLIB_NAMES.items():
        if not isinstance(table[key], (int, float)):
            raise ValueError(f"{key}={table[key]!r}: only constant values map to RLlib "
                             f"(no 'lin_X' schedules)")
        training[name] = table[key]
    batch = settings.train_batch_size or table["n_steps"] * table["n_envs"]
    if training["minibatch_size"] > batch:
        raise ValueError(f"batch_size {training['minibatch_size']} exceeds the "
                         f"{batch} env steps of one iteration")
    register_env(RLLIB_ENV, make_env)
    env_config = {"env_id": settings.env_id,
                  **table.get("env_kwargs", {}), **settings.env_kwargs}
    return (PPOConfig()
            .environment(RLLIB_ENV, env_config=env_config)
            .env_runners(num_env_runners=settings.num_env_runners,
                         num_envs_per_env_runner=settings.num_envs_per_env_runner)
            .training(train_batch_size_per_learner=batch, use_kl_loss=False,
                      vf_clip_param=math.inf, **training)
            .rl_module(model_config=DefaultModelConfig(conv_filters=CONV_FILTERS,
                                                       head_fcnet_hiddens=[256],
                                                       vf_share_layers=True))
            .debugging(seed=settings.seed))


@dataclass
class IterationSummary:
    """What one ``algo.train()`` reported: env steps sampled (this iteration and since
    the start), episodes finished, their mean return (NaN when none finished), the
    learner's mean PPO losses and entropy, and the iteration's wall time in s."""

    env_steps: int
    env_steps_lifetime: int
    episodes: int
    episode_return_mean: float
    policy_loss: float
    vf_loss: float
    entropy: float
    seconds: float


def summarize(result: dict[str, Any]) -> IterationSummary:
    """The :class:`IterationSummary` of an ``algo.train()`` result (new API stack keys)."""
    runners, learner = result["env_runners"], result["learners"]["default_policy"]
    return IterationSummary(
        env_steps=int(runners["num_env_steps_sampled"]),
        env_steps_lifetime=int(runners["num_env_steps_sampled_lifetime"]),
        episodes=int(runners.get("num_episodes", 0)),
        episode_return_mean=float(runners.get("episode_return_mean", math.nan)),
        policy_loss=float(learner["policy_loss"]), vf_loss=float(learner["vf_loss"]),
        entropy=float(learner["entropy"]), seconds=float(result["time_this_iter_s"]))


def main(argv: list[str] | None = None) -> int:
    parser = command_parser("python -m homing_train.learning.rllib_ppo", __doc__)
    parser.add_argument("--address", default=None,
                        help="Ray cluster address ('auto': the cluster of `ray start`); "
                             "default: a local Ray")
    parser.add_argument("--env", default=RllibSettings.env_id)
    parser.add_argument("--env-kwargs", type=json.loads, default={}, metavar="JSON")
    parser.add_argument("--env-runners", type=int, default=2)
    parser.add_argument("--envs-per-runner", type=int, default=1)
    parser.add_argument("--train-batch-size", type=int, default=None,
                        help="env steps per iteration (default: n_steps x n_envs of ppo.yml)")
    parser.add_argument("--iterations", type=int, default=100)
    parser.add_argument("--seed", type=seed_value, default=0)
    parser.add_argument("--out", type=Path, default=None,
                        help="folder for the final checkpoint (algo.save_to_path)")
    args = parser.parse_args(argv)
    try:
        settings = RllibSettings(args.env, args.env_kwargs, args.env_runners,
                                 args.envs_per_runner, args.train_batch_size, seed=args.seed)
    except ValueError as err:
        parser.error(str(err))
    if args.iterations < 1:
        parser.error(f"--iterations must be >= 1, got {args.iterations}")
    import ray

    # --import modules reach the env runners on every node through homing_gym's variable
    ray.init(address=args.address, runtime_env={"env_vars": {
        IMPORT_VARIABLE: os.environ.get(IMPORT_VARIABLE, "")}})
    algo = ppo_config(settings).build_algo()
    start = time.perf_counter()
    for i in range(args.iterations):
        s = summarize(algo.train())
        print(f"iteration {i + 1}: {s.env_steps_lifetime} env steps, {s.episodes} episodes, "
              f"return {s.episode_return_mean:.2f}, policy loss {s.policy_loss:.4f}, "
              f"{s.seconds:.1f} s ({time.perf_counter() - start:.0f} s in all)")
    if args.out is not None:
        print(f"checkpoint: {algo.save_to_path(args.out.resolve())}")
    algo.stop()
    ray.shutdown()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
