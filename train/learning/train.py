"""``homing-train``: PPO (stable-baselines3) on any homing-gym env, one folder per run.

    homing-train --env homing_gym/LocalHoming-v0 --seed 0 --timesteps 300000 --out runs/ppo
    homing-train --resume runs/ppo          # continue from the last checkpoint
    homing-train --recipe ppo_procedural_long --seed 1 --out runs/long_s1   # a shipped recipe

Hyperparameters come from ``train/learning/hyperparams/ppo.yml`` (keyed by env id, with a
``default`` entry), or ``--hyperparams FILE``, or ``--recipe NAME`` (the settings a shipped
policy, or one shipped before, was trained with, recorded in its ``.yml``), then ``--hp
KEY=VALUE`` (values parsed as YAML), then the dedicated flags. A run folder holds
``model.zip`` (final), ``best_model.zip`` and ``evaluations.npz`` (``EvalCallback`` on
held-out seeds, with success rates), ``checkpoints/``, ``config.yml``, ``command.txt``,
``versions.json``, ``summary.json`` (timesteps, wall time, env steps per second of
``learn()``), TensorBoard logs in ``tb/`` and ``learning_curve.png``; with a ``curriculum``,
``curriculum.json`` (the stages reached and when).

A new run needs a new or empty ``--out`` (an existing run is continued with ``--resume``),
and a run folder has one ``homing-train`` at a time. Every save is atomic (a temporary
file renamed over the old one), so a kill or a full disk never leaves a torn file;
``--resume`` continues from the newest intact checkpoint, skipping a torn one (a warning).
"""

from __future__ import annotations

import json
import math
import multiprocessing
import os
import platform
import re
import shlex
import shutil
import signal
import sys
import tempfile
import time
import traceback
import zipfile
import zlib
from collections.abc import Sequence
from dataclasses import asdict, dataclass, field, fields
from functools import partial
from importlib import resources
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np
import yaml

import homing_gym
from homing_gym.cli import command_parser, seed_value
from homing_train import DEFAULT_ENV
from homing_train.extras import MissingExtraError, require_extra
from homing_train.harness.protocols import UNSEEN_SEED
from homing_train.learning import EXTRACTORS
from homing_train.learning.curriculum import (HOOK, CurriculumSettings, last_stage, mark_stages,
                                              plot_training_success)
from homing_train.learning.imitation import dagger
from homing_train.learning.thread_split import phase_threads
from homing_train.learning.ppo_settings import (PPO_KEYS, check_device, check_ppo,
                                               extractor_arguments, ppo_arguments)
from homing_train.learning.pretrain import pretrain
from homing_gym.outputs import (OutputLock, checked_output_dir, save_figure,
                                write_text_atomic)

HYPERPARAMS = Path(str(resources.files("homing_train.learning") / "hyperparams" / "ppo.yml"))
#: The records (``NAME.yml``) of policies no longer shipped, for ``--recipe NAME``.
RECIPES = Path(str(resources.files("homing_train.learning") / "recipes"))
EVAL_SEED_OFFSET = 1_000_000
IMITATION_SEED_OFFSET = 2_000_000
PRETRAIN_SEED_OFFSET = 3_000_000


def seed_ranges(config: "TrainConfig", done_steps: int = 0) -> dict[str, range]:
    """The episode seeds a run (resumed after ``done_steps``) draws worlds from: its
    training envs (env ``i`` starts in the world of its seed), the evaluation callback's
    held-out training worlds, DAgger's and pretraining's."""
    s, scenes = config.seed, config.n_scenes
    imitation = max(config.imitation_iterations, 1) * config.imitation_episodes
    pretraining = config.pretrain_scenes + config.pretrain_scenes // 4 + 1 if (
        config.pretrain_samples) else 0
    return {"training": range(s + done_steps, s + done_steps + config.n_envs),
            "evaluation": range(s + EVAL_SEED_OFFSET, s + EVAL_SEED_OFFSET + scenes),
            "imitation": range(s + IMITATION_SEED_OFFSET, s + IMITATION_SEED_OFFSET
                               + (imitation if config.imitation_iterations else 0)),
            "pretraining": range(s + PRETRAIN_SEED_OFFSET, s + PRETRAIN_SEED_OFFSET
                                 + pretraining)}


def check_seed_ranges(config: "TrainConfig", done_steps: int = 0) -> None:
    """``ValueError`` if a run would draw worlds the protocols hold out (seeds from
    ``unseen``'s 10,000,000 on) or train on the worlds it selects models on."""
    ranges = {name: r for name, r in seed_ranges(config, done_steps).items() if len(r)}
    too_high = [f"{name} {r.start}-{r.stop - 1}" for name, r in ranges.items()
                if r.stop > UNSEEN_SEED]
    if too_high:
        raise ValueError(f"seed {config.seed} would draw held-out worlds (the protocols' "
                         f"seeds from {UNSEEN_SEED}): {', '.join(too_high)}; use a smaller "
                         f"--seed")
    names = list(ranges)
    for i, a in enumerate(names):
        for b in names[i + 1:]:
            if ranges[a].start < ranges[b].stop and ranges[b].start < ranges[a].stop:
                raise ValueError(f"the {a} seeds {ranges[a].start}-{ranges[a].stop - 1} "
                                 f"overlap the {b} seeds {ranges[b].start}-"
                                 f"{ranges[b].stop - 1} (after {done_steps} steps): the run "
                                 f"would train on worlds it evaluates on; use fewer steps")


def _integer(value: Any) -> bool:
    return isinstance(value, int) and not isinstance(value, bool)


@dataclass
class TrainConfig:
    """Everything that defines a run (written to ``config.yml``)."""

    env_id: str
    seed: int = 0
    timesteps: int = 300_000
    n_envs: int = 2
    vec: str = "subproc"
    workers: int | None = None        # processes: "subproc" (None: one per env), "native" (None: 1)
    device: str = "cpu"
    torch_threads: int = 1
    extractor: str = "panorama"
    features_dim: int = 256
    extractor_kwargs: dict = field(default_factory=dict)
    env_kwargs: dict = field(default_factory=dict)
    eval_freq: int = 10_000
    eval_episodes: int = 20
    eval_deterministic: bool = True
    checkpoint_freq: int = 10_000
    imitation_iterations: int = 0
    imitation_episodes: int = 40
    imitation_epochs: int = 4
    pretrain_samples: int = 0
    pretrain_positions: int = 4000
    pretrain_scenes: int = 1
    warm_start_learning_rate: float = 3e-4
    init_policy: str | None = None
    critic_warmup_steps: int = 0
    curriculum: dict | None = None
    augment: dict | None = None
    ppo: dict = field(default_factory=dict)

    def __post_init__(self) -> None:
        # homing-gym's ids, or a user's (--import)
        if not isinstance(self.env_id, str) or self.env_id not in gym.registry:
            raise ValueError(f"unknown env {self.env_id!r}; homing-gym ids: "
                             f"{list(homing_gym.ENV_IDS)} (or register yours, --import MODULE)")
        if self.vec not in VECS:
            raise ValueError(f"--vec must be one of {VECS}, got {self.vec!r}")
        if self.workers is not None and not (_integer(self.workers)
                                             and 1 <= self.workers <= self.n_envs):
            raise ValueError(f"workers must be an integer from 1 to n_envs ({self.n_envs}), "
                             f"got {self.workers!r}")
        if self.extractor not in EXTRACTORS:
            raise ValueError(f"unknown extractor {self.extractor!r}; allowed: {EXTRACTORS}")
        for key in ("timesteps", "n_envs", "eval_freq", "eval_episodes", "checkpoint_freq",
                    "torch_threads", "imitation_episodes", "imitation_epochs",
                    "pretrain_positions", "pretrain_scenes", "features_dim"):
            value = getattr(self, key)
            if not (_integer(value) and value >= 1):
                raise ValueError(f"{key} must be an integer >= 1, got {value!r}")
        for key in ("seed", "imitation_iterations", "pretrain_samples", "critic_warmup_steps"):
            value = getattr(self, key)
            if not (_integer(value) and value >= 0):
                raise ValueError(f"{key} must be an integer >= 0, got {value!r}")
        for key in ("env_kwargs", "ppo"):
            if not isinstance(getattr(self, key), dict):
                raise ValueError(f"{key} must be a mapping, got {getattr(self, key)!r}")
        if not isinstance(self.device, str):
            raise ValueError(f"device must be a torch device name, e.g. 'cpu', got "
                             f"{self.device!r}")
        rate = self.warm_start_learning_rate
        if not (isinstance(rate, (int, float)) and math.isfinite(rate) and rate > 0):
            raise ValueError(f"warm_start_learning_rate must be a positive number, got {rate!r}")
        if self.init_policy is not None and not (isinstance(self.init_policy, str)
                                                 and Path(self.init_policy).is_file()):
            raise ValueError(f"init_policy {self.init_policy!r} is not a file (give a saved "
                             f"stable-baselines3 PPO .zip)")
        if not isinstance(self.eval_deterministic, bool):
            raise ValueError(f"eval_deterministic must be true or false, got "
                             f"{self.eval_deterministic!r}")
        check_ppo(self.ppo, self.n_envs)
        extractor_arguments(self.extractor, self.extractor_kwargs)
        check_device(self.device)
        if self.curriculum is not None:
            CurriculumSettings.from_value(self.curriculum)
        if self.augment is not None:
            from homing_train.learning.augment import AugmentSettings

            AugmentSettings.from_value(self.augment)
        scenes = self.env_kwargs.get("scene")
        if isinstance(scenes, list):
            if not scenes or not all(isinstance(name, str) for name in scenes):
                raise ValueError(f"env_kwargs scene: a scene name or a non-empty list of "
                                 f"scene names, got {scenes!r}")
            if self.imitation_iterations:
                raise ValueError("a list of scenes is for PPO's envs and pretraining; DAgger "
                                 "takes one scene (env_kwargs scene: NAME)")
            if self.pretrain_samples and self.pretrain_scenes < len(scenes):
                raise ValueError(f"pretraining on {len(scenes)} scenes needs pretrain_scenes "
                                 f">= {len(scenes)} (instance s builds scene[s % "
                                 f"{len(scenes)}]), got {self.pretrain_scenes}")

    def env_kwargs_of(self, rank: int) -> dict:
        """The env kwargs of vector env ``rank``: with a list of scenes, env ``rank``
        builds ``scene[rank % len(scene)]`` (e.g. both procedural generators at once)."""
        scenes = self.env_kwargs.get("scene")
        if isinstance(scenes, list):
            return {**self.env_kwargs, "scene": scenes[rank % len(scenes)]}
        return self.env_kwargs

    @property
    def curriculum_settings(self) -> CurriculumSettings | None:
        """The checked ``curriculum`` setting, or ``None`` without one."""
        return None if self.curriculum is None else CurriculumSettings.from_value(self.curriculum)

    @property
    def n_scenes(self) -> int:
        """How many scenes the envs cycle through (1 unless ``scene`` is a list)."""
        scenes = self.env_kwargs.get("scene")
        return len(scenes) if isinstance(scenes, list) else 1


def load_hyperparams(env_id: str, path: Path = HYPERPARAMS) -> dict[str, Any]:
    """The ``default`` entry of a YAML hyperparameter file updated by ``env_id``'s entry."""
    try:
        table = yaml.safe_load(Path(path).read_text()) or {}
    except (OSError, UnicodeDecodeError, yaml.YAMLError) as err:
        raise ValueError(f"cannot read hyperparameter file {path}: "
                         f"{' '.join(str(err).split())}") from err
    if not isinstance(table, dict):
        raise ValueError(f"hyperparameter file {path} must map env ids to settings")
    entries = {key: table.get(key) or {} for key in ("default", env_id)}
    for key, entry in entries.items():
        if not isinstance(entry, dict):
            raise ValueError(f"hyperparameter file {path}: {key!r} must map setting names "
                             f"to values, got {entry!r}")
    return {**entries["default"], **entries[env_id]}


def recipe(name: str, folders: Sequence[Path] | None = None) -> tuple[str, dict[str, Any]]:
    """The env id and the settings (as :func:`make_config` takes them: PPO's keys at the top
    level) that the policy ``name`` was trained with: the ``config`` recorded in
    ``train/shipped/NAME.yml`` (a shipped policy) or ``train/learning/recipes/NAME.yml``
    (one no longer shipped); ``folders``: other folders of such records."""
    from homing_train.harness.policies import POLICY_DIR

    folders = (POLICY_DIR, RECIPES) if folders is None else folders
    recorded = {p.stem: p for folder in folders for p in sorted(Path(folder).glob("*.yml"))}
    if name not in recorded:
        raise ValueError(f"unknown recipe {name!r}; allowed (shipped policies and the "
                         f"recipes of earlier ones): {sorted(recorded)}")
    config = (yaml.safe_load(recorded[name].read_text()) or {}).get("config")
    if not isinstance(config, dict) or "env_id" not in config:
        raise ValueError(f"{recorded[name]} records no training config (no 'config' with an "
                         f"'env_id'); its recipe cannot be rerun")
    settings = {k: v for k, v in config.items() if k not in ("env_id", "ppo")}
    return config["env_id"], {**settings, **(config.get("ppo") or {})}


def parse_overrides(items: list[str]) -> dict[str, Any]:
    """``["n_steps=128", "env_kwargs={scene: arena}"]`` -> values parsed as YAML."""
    out = {}
    for item in items:
        if "=" not in item:
            raise ValueError(f"--hp expects KEY=VALUE, got {item!r}")
        key, value = item.split("=", 1)
        try:
            out[key.strip()] = yaml.safe_load(value)
        except yaml.YAMLError as err:
            raise ValueError(f"--hp {item!r}: the value is not valid YAML ({err})") from err
    return out


def make_config(env_id: str, settings: dict[str, Any], **flags: Any) -> TrainConfig:
    """Merge hyperparameter settings and command-line flags into a :class:`TrainConfig`."""
    settings = {**settings, **{k: v for k, v in flags.items() if v is not None}}
    names = {f.name for f in fields(TrainConfig)} - {"env_id", "ppo"}
    ppo = {k: settings.pop(k) for k in list(settings) if k in PPO_KEYS}
    unknown = sorted(set(settings) - names)
    if unknown:
        raise ValueError(f"unknown settings {unknown}; allowed: {sorted(names) + list(PPO_KEYS)}")
    return TrainConfig(env_id=env_id, ppo=ppo, **settings)


class EnvWorkerError(RuntimeError):
    """An env in a subprocess worker raised: the message is the worker's own error (SB3's
    ``SubprocVecEnv`` would only say ``EOFError``)."""


class _ReportErrors(gym.Wrapper):
    """In a worker process: an error from ``reset``/``step`` is written to ``path`` (its
    type, message and traceback) and the worker exits quietly, so that the main process
    says that error once instead of SB3's ``EOFError`` and a second traceback."""

    def __init__(self, env: gym.Env, path: Path):
        super().__init__(env)
        self._path = path

    def _fail(self, err: Exception) -> None:
        self._path.write_text(f"{type(err).__name__}: {err}\n\n{traceback.format_exc()}")
        os._exit(1)

    def reset(self, **kwargs):
        try:
            return self.env.reset(**kwargs)
        except Exception as err:  # noqa: BLE001 (reported to the main process)
            self._fail(err)

    def step(self, action):
        try:
            return self.env.step(action)
        except Exception as err:  # noqa: BLE001 (reported to the main process)
            self._fail(err)


def make_env(env_id: str, env_kwargs: dict[str, Any], report_dir: str | None = None) -> gym.Env:
    """A single env (top-level, so that subprocess workers can unpickle it). In a worker
    process Ctrl-C is left to the main process, which saves the run and closes the
    workers, and an env error is written to ``report_dir`` for the main process to say
    (:class:`EnvWorkerError`)."""
    import homing_gym  # noqa: F401  (registers the ids in a spawned worker)

    env = gym.make(env_id, **env_kwargs)
    if multiprocessing.current_process().name != "MainProcess":
        signal.signal(signal.SIGINT, signal.SIG_IGN)
        if report_dir is not None:
            env = _ReportErrors(env, Path(report_dir) / f"worker_{os.getpid()}.txt")
    return env


def make_monitored_env(env_id: str, env_kwargs: dict[str, Any],
                       report_dir: str | None = None) -> gym.Env:
    """:func:`make_env` in SB3's ``Monitor`` (episode returns, lengths and successes)."""
    from stable_baselines3.common.monitor import Monitor

    return Monitor(make_env(env_id, env_kwargs, report_dir), info_keywords=("is_success",))


def worker_error(report_dir: Path) -> EnvWorkerError | None:
    """The first error a worker wrote to ``report_dir`` (its one-line summary as the
    message, the traceback in ``details``), or ``None``."""
    reports = sorted(report_dir.glob("worker_*.txt"))
    if not reports:
        return None
    text = reports[0].read_text()
    error = EnvWorkerError(f"an env worker failed: {text.splitlines()[0]}")
    error.details = text
    return error


def make_vec(config: TrainConfig, n_envs: int, seed: int, report_dir: Path | None = None,
             augmented: bool = True):
    """A monitored vector env of ``n_envs`` envs (env ``i``: :meth:`TrainConfig.env_kwargs_of`
    ``(i)``, seed ``seed + i``; success logged from ``is_success``), images transposed to
    channel-first; subprocess workers write their errors to ``report_dir``. With
    ``vec="subproc"``, one process per env, or ``config.workers`` processes each stepping
    a group of envs (:class:`~homing_train.learning.grouped_vec_env.GroupedSubprocVecEnv`);
    with ``vec="native"``, homing-gym's native vector env in this process or
    ``config.workers`` processes (:mod:`homing_train.learning.native_vec_env`). With
    ``config.augment`` and ``augmented`` (the training envs, not the evaluation's), each
    episode's images in its own colours (:mod:`homing_train.learning.augment`)."""
    from stable_baselines3.common.vec_env import DummyVecEnv, SubprocVecEnv, VecTransposeImage

    from homing_train.learning.grouped_vec_env import GroupedSubprocVecEnv
    from homing_train.learning.native_vec_env import native_vec_env

    if config.vec == "native":
        env = native_vec_env(config.env_id, [config.env_kwargs_of(r) for r in range(n_envs)],
                             processes=config.workers or 1)
        env.seed(seed)
        return VecTransposeImage(_augmented(env, config, seed, augmented))
    report = None if report_dir is None else str(report_dir)
    fns = [partial(make_monitored_env, config.env_id, config.env_kwargs_of(rank), report)
           for rank in range(n_envs)]
    workers = min(config.workers or n_envs, n_envs)
    if config.vec == "dummy" or n_envs == 1:
        env = DummyVecEnv(fns)
    elif workers < n_envs:
        env = GroupedSubprocVecEnv(fns, workers, start_method="spawn")
    else:
        env = SubprocVecEnv(fns, start_method="spawn")
    env.seed(seed)
    # channel-first images, as SB3 would wrap them itself
    return VecTransposeImage(_augmented(env, config, seed, augmented))


def _augmented(env, config: TrainConfig, seed: int, augmented: bool):
    """``env`` with ``config.augment``'s colour transforms where ``augmented``."""
    if config.augment is None or not augmented:
        return env
    from homing_train.learning.augment import AugmentedImages, AugmentSettings

    return AugmentedImages(env, AugmentSettings.from_value(config.augment), seed)


def versions() -> dict[str, str]:
    """Versions of the software a run depends on."""
    import pybullet
    import stable_baselines3
    import torch

    return {"python": platform.python_version(), "homing_gym": homing_gym.__version__,
            "stable_baselines3": stable_baselines3.__version__, "torch": torch.__version__,
            "gymnasium": gym.__version__, "numpy": np.__version__,
            "pybullet": str(getattr(pybullet, "__version__", "3.2.x")),
            "platform": platform.platform()}


def checkpoint_steps(path: Path) -> int:
    """Env steps of a checkpoint named ``ppo_<steps>_steps.zip``."""
    match = re.search(r"ppo_(\d+)_steps", Path(path).name)
    if match is None:
        raise ValueError(f"{path}: not a checkpoint name ppo_<steps>_steps.zip")
    return int(match.group(1))


def model_zip_fault(path: Path) -> str | None:
    """Why the saved model at ``path`` cannot be loaded whole (a save torn by a kill or a
    full disk), or ``None`` when it is a zip holding SB3's ``data`` and ``policy.pth``
    whose every member reads back with its checksum."""
    try:
        with zipfile.ZipFile(path) as archive:
            bad = archive.testzip()
            missing = sorted({"data", "policy.pth"} - set(archive.namelist()))
    except (OSError, EOFError, ValueError, zlib.error, zipfile.BadZipFile) as err:
        return f"{type(err).__name__}: {err}"
    if bad is not None:
        return f"its member {bad!r} is damaged"
    return f"no {missing} in it (not a stable-baselines3 save)" if missing else None


def latest_checkpoint(run: Path, torn: list[tuple[Path, str]] | None = None) -> Path | None:
    """The intact checkpoint with the most steps in ``run/checkpoints``, if any; the
    newer torn ones passed over are appended to ``torn`` as ``(path, why)``."""
    found = sorted(((int(m.group(1)), p) for p in (run / "checkpoints").glob("ppo_*_steps.zip")
                    if (m := re.fullmatch(r"ppo_(\d+)_steps\.zip", p.name))), reverse=True)
    for _, path in found:
        fault = model_zip_fault(path)
        if fault is None:
            return path
        if torn is not None:
            torn.append((path, fault))
    return None


def plot_learning_curve(run: Path) -> Path | None:
    """``learning_curve.png`` from ``evaluations.npz``: mean return and success rate; with
    a ``pretrain.json``, a first panel of the pretraining's agreement with the oracle; with
    a ``curriculum.json``, the stages marked and a last panel of the training episodes'
    success rate (:func:`~homing_train.learning.curriculum.plot_training_success`)."""
    data_path = run / "evaluations.npz"
    if not data_path.is_file():
        return None
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    data = np.load(data_path)
    steps = data["timesteps"]
    pretrained = run / "pretrain.json"
    stages = last_stage(run / "curriculum.json")[1]
    panels = 1 + pretrained.is_file() + bool(stages)
    fig, axes = plt.subplots(1, panels, figsize=(6 * panels, 3.5), constrained_layout=True)
    axes = list(np.atleast_1d(axes))
    if pretrained.is_file():
        record = json.loads(pretrained.read_text())
        axes[0].plot(record["samples"], 100 * np.asarray(record["agreement"]),
                     color="tab:purple")
        axes[0].set_xlabel("pretraining samples (rendered pose pairs)")
        axes[0].set_ylabel("agreement with the oracle (%)")
        axes[0].set_ylim(0, 100)
        axes[0].set_title("pretraining: validation positions")
    if stages:
        plot_training_success(axes.pop(), run / "tb", stages)
    ax = axes[-1]
    ax.plot(steps, data["results"].mean(axis=1), color="tab:blue", marker="o", ms=3)
    ax.set_xlabel("environment steps")
    ax.set_ylabel("mean evaluation return", color="tab:blue")
    if "successes" in data and data["successes"].size:
        ax2 = ax.twinx()
        ax2.plot(steps, 100 * data["successes"].mean(axis=1), color="tab:green", marker="s",
                 ms=3)
        ax2.set_ylabel("success rate (%)", color="tab:green")
        ax2.set_ylim(0, 100)
    mark_stages(ax, stages)
    ax.set_title(f"{run.name}: evaluation on held-out seeds")
    out = run / "learning_curve.png"
    save_figure(fig, out, dpi=100)
    plt.close(fig)
    return out


def _restore_evaluations(callback, run: Path) -> None:
    """Let a resumed run's ``EvalCallback`` append to the evaluations already logged."""
    path = run / "evaluations.npz"
    if not path.is_file():
        return
    try:
        with np.load(path) as data:
            steps, results, lengths = (list(data[key]) for key in
                                       ("timesteps", "results", "ep_lengths"))
            successes = list(data["successes"]) if "successes" in data else []
    except (OSError, ValueError, EOFError, KeyError, zipfile.BadZipFile) as err:
        raise ValueError(f"{path} cannot be read ({type(err).__name__}: {err}): move it "
                         f"aside to resume without the earlier evaluations") from err
    callback.evaluations_timesteps = steps
    callback.evaluations_results = [list(r) for r in results]
    callback.evaluations_length = [list(r) for r in lengths]
    callback.evaluations_successes = [list(r) for r in successes]
    if results:
        callback.best_mean_reward = float(np.max(np.mean(results, axis=1)))


def previous_sessions(summary: Path) -> list[dict]:
    """The training sessions recorded in a run's ``summary.json`` (none without one)."""
    if not summary.is_file():
        return []
    try:
        sessions = json.loads(summary.read_text())["sessions"]
    except (OSError, ValueError, KeyError, TypeError) as err:
        raise ValueError(f"{summary} cannot be read ({type(err).__name__}: {err}): move it "
                         f"aside to resume without the earlier sessions' record") from err
    if not isinstance(sessions, list):
        raise ValueError(f"{summary}: 'sessions' must be a list, got {sessions!r}")
    return sessions


def _raise_interrupt(signum, frame) -> None:
    """A signal handler that stops training as Ctrl-C does."""
    raise KeyboardInterrupt(f"signal {signum}")


def set_actor_trainable(policy, trainable: bool) -> None:
    """Freeze (``trainable=False``) or release every parameter of an SB3 actor-critic
    policy except the critic's own layers (value MLP and head, and its features extractor
    when not shared): PPO updates then fit the value function alone."""
    critic = [policy.mlp_extractor.value_net, policy.value_net]
    if not policy.share_features_extractor:
        critic.append(policy.vf_features_extractor)
    critic_ids = {id(p) for module in critic for p in module.parameters()}
    for parameter in policy.parameters():
        if id(parameter) not in critic_ids:
            parameter.requires_grad_(trainable)


def load_policy_weights(model, path: str | Path) -> None:
    """Copy the policy network (extractor, actor and critic) of the PPO model saved at
    ``path`` into ``model``; the two networks must have the same layout."""
    from homing_train.learning.policy_zip import load_policy

    source = load_policy(path)
    try:
        model.policy.load_state_dict(source.policy.state_dict())
    except RuntimeError as err:
        raise ValueError(f"init_policy {str(path)!r} does not fit this run's network (same "
                         f"env kwargs, extractor and features_dim needed): {err}") from err


def warm_starts(config: TrainConfig, progress: bool = True) -> list[tuple[str, Any]]:
    """The warm starts the run asks for, in order, as ``(name, fit)`` with ``fit(model)``
    returning a dataclass record: behaviour cloning on rendered pose pairs
    (``pretrain_samples``), then DAgger (``imitation_iterations``)."""
    steps = []
    if config.pretrain_samples:
        steps.append(("pretrain", partial(
            pretrain, env_id=config.env_id, env_kwargs=config.env_kwargs,
            positions=config.pretrain_positions, scenes=config.pretrain_scenes,
            samples=config.pretrain_samples, seed=config.seed + PRETRAIN_SEED_OFFSET,
            progress=progress)))
    if config.imitation_iterations:
        steps.append(("imitation", partial(
            dagger, env_id=config.env_id, env_kwargs=config.env_kwargs,
            iterations=config.imitation_iterations, episodes=config.imitation_episodes,
            epochs=config.imitation_epochs, seed=config.seed + IMITATION_SEED_OFFSET,
            progress=progress)))
    return steps


def check_curriculum(env: gym.Env, curriculum: CurriculumSettings) -> None:
    """Raise ``ValueError`` unless the unwrapped ``env`` has the curriculum's hook and
    accepts every stage (its own checks: success radius, scene size); ``env`` is left at
    the last stage."""
    hook = getattr(env, HOOK, None)
    if hook is None:
        raise ValueError(f"curriculum: {type(env).__name__} has no {HOOK}() to change its "
                         f"start distance (LocalHoming-v0 has one)")
    for i, stage in enumerate(curriculum.start_distance):
        try:
            hook(stage, **curriculum.stage_kwargs(i))
        except ValueError as err:
            raise ValueError(f"curriculum stage {i}: {err}") from err


#: How ``homing-train`` may run its envs (``--vec``).
VECS = ("subproc", "dummy", "native")
#: memory of one subprocess env worker (279 MiB unique to it, measured with a LocalHoming-v0
#: env at 16x64: Python, torch, PyBullet and the world)
WORKER_MEMORY = 300 * 2**20


def check_memory(config: TrainConfig, observation_space: gym.Space) -> None:
    """``ValueError`` when the run's rollout buffer (``n_steps`` x ``n_envs`` observations
    as float32), its policy's MLP after the extractor (float32 weights, gradients and
    Adam's two moments: 16 bytes a parameter) or its env worker processes
    (:data:`WORKER_MEMORY` each) need more than this machine's memory."""
    memory = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    processes = {"subproc": min(config.workers or config.n_envs, config.n_envs)
                 if config.n_envs > 1 else 0,
                 "native": config.workers if (config.workers or 1) > 1 else 0,
                 "dummy": 0}[config.vec]
    n_steps = config.ppo.get("n_steps", 2048)
    values = gym.spaces.flatdim(observation_space)
    rollout = 4 * n_steps * config.n_envs * values
    arch = config.ppo.get("policy_kwargs", {}).get("net_arch", [64, 64])
    heads = list(arch.values()) if isinstance(arch, dict) else [arch, arch]
    parameters = sum(a * b for widths in heads
                     for a, b in zip([config.features_dim, *widths], widths))
    for need, what, fix in (
            (rollout, f"the rollout buffer (n_steps {n_steps} x n_envs {config.n_envs} x "
                      f"{values} observation values x 4 bytes)", "fewer n_steps or n_envs"),
            (16 * parameters, f"the policy's MLP (net_arch {arch} after features_dim "
                              f"{config.features_dim}: {parameters} parameters x 16 bytes)",
             "narrower layers"),
            (processes * WORKER_MEMORY, f"{processes} env worker processes (--vec "
                                        f"{config.vec}, about {WORKER_MEMORY // 2**20} MiB "
                                        f"each)",
             "fewer n_envs, or fewer workers (--hp workers=N steps the envs in N "
             "processes)")):
        if need > memory:
            raise ValueError(f"{what} would take {need / 2**30:.1f} GiB, more than this machine's "
                             f"{memory / 2**30:.1f} GiB of memory; use {fix}")


def new_model(config: TrainConfig, env, **kwargs):
    """A fresh PPO model of ``config`` on the vectorised ``env`` (``kwargs``: more PPO
    arguments, e.g. ``tensorboard_log``)."""
    from stable_baselines3 import PPO

    from homing_train.learning.extractor import policy_kwargs_for

    extractor_kwargs = ({"features_dim": config.features_dim,
                         **extractor_arguments(config.extractor, config.extractor_kwargs)}
                        if config.extractor != "combined" else {})
    if config.ppo.get("use_sde") and not isinstance(env.action_space, gym.spaces.Box):
        raise ValueError(f"use_sde needs continuous actions (action_type='continuous'); "
                         f"this env's action space is {env.action_space}")
    ppo = ppo_arguments(config.ppo)
    policy_kwargs = {**policy_kwargs_for(config.extractor, **extractor_kwargs),
                     **ppo.pop("policy_kwargs")}
    return PPO("MultiInputPolicy", env, seed=config.seed, device=config.device, verbose=0,
               policy_kwargs=policy_kwargs, **ppo, **kwargs)


def train(config: TrainConfig, out: Path, resume: bool = False,
          command: str | None = None, progress: bool = True):
    """Train (or, with ``resume``, continue) a run in folder ``out``; returns the model."""
    from stable_baselines3 import PPO
    import torch

    from homing_train.learning.checkpoints import (AtomicCheckpointCallback, AtomicEvalCallback,
                                                   save_model)
    from homing_train.learning.curriculum_callback import CurriculumCallback

    # One intra-op thread by default: with the env workers on the same cores, torch's
    # thread pool spins against them and learn() ran 4x slower on 2 cores (docs/training.md).
    torch.set_num_threads(config.torch_threads)
    # a bad env setting fails here, once, with its own message, before the run folder is
    # written (in a subprocess worker it would surface as a broken pipe)
    probe = make_env(config.env_id, config.env_kwargs_of(0))
    # the renderer and physics in effect are recorded, so that the policy is evaluated
    # with them (homing_train.learning.ship) even after a default changes
    made = probe.unwrapped
    config.env_kwargs.setdefault("renderer", made.camera.config.renderer)
    config.env_kwargs.setdefault("physics_substeps", made.physics_substeps)
    curriculum = config.curriculum_settings
    if curriculum is not None:
        check_curriculum(made, curriculum)
    probe.close()
    check_memory(config, probe.observation_space)
    checkpoint = latest_checkpoint(out) if resume else None
    # a resumed run draws new training episodes: its envs are seeded past the steps done
    done_steps = checkpoint_steps(checkpoint) if checkpoint is not None else 0
    check_seed_ranges(config, done_steps)
    out.mkdir(parents=True, exist_ok=True)
    for stale in (*out.glob(".*.tmp"), *out.glob("checkpoints/.*.tmp")):
        stale.unlink()          # the temporary of a save cut by a kill (the run is locked)
    write_text_atomic(out / "config.yml", yaml.safe_dump(asdict(config), sort_keys=False))
    commands = out / "command.txt"
    # the installed command's name, not this machine's path to it
    write_text_atomic(commands, (commands.read_text() if commands.is_file() else "")
                      + (command or shlex.join(["homing-train", *sys.argv[1:]])) + "\n")
    write_text_atomic(out / "versions.json", json.dumps(versions(), indent=2))
    report_dir = Path(tempfile.mkdtemp(prefix="homing-train-workers-"))
    env = make_vec(config, config.n_envs, config.seed + done_steps, report_dir)
    eval_env = make_vec(TrainConfig(**{**asdict(config), "vec": "dummy"}), config.n_scenes,
                        config.seed + EVAL_SEED_OFFSET, augmented=False)
    try:
        if checkpoint is not None:
            model = PPO.load(checkpoint, env=env, device=config.device,
                             tensorboard_log=str(out / "tb"))
            model._last_obs = None      # learn() resets the envs, with their new seeds
        else:
            model = new_model(config, env, tensorboard_log=str(out / "tb"))
            if config.init_policy:
                load_policy_weights(model, config.init_policy)
            for name, warm_start in warm_starts(config, progress):
                # the warm starts' own step size; PPO sets its schedule's again in train()
                for group in model.policy.optimizer.param_groups:
                    group["lr"] = config.warm_start_learning_rate
                record = warm_start(model)
                write_text_atomic(out / f"{name}.json", json.dumps(asdict(record), indent=2))
                save_model(model, out / f"{name}_model.zip")
        start_steps = model.num_timesteps
        remaining = config.timesteps - start_steps
        eval_cb = AtomicEvalCallback(eval_env, out, n_eval_episodes=config.eval_episodes,
                                     eval_freq=max(config.eval_freq // config.n_envs, 1),
                                     deterministic=config.eval_deterministic, verbose=0)
        if checkpoint is not None:
            _restore_evaluations(eval_cb, out)
        ckpt_cb = AtomicCheckpointCallback(max(config.checkpoint_freq // config.n_envs, 1),
                                           str(out / "checkpoints"), name_prefix="ppo")
        callbacks = [eval_cb, ckpt_cb, phase_threads(config.torch_threads)]
        if curriculum is not None:     # a resumed run goes on at the stage it had reached
            stage, history = (last_stage(out / "curriculum.json") if checkpoint is not None
                              else (0, []))
            callbacks.append(CurriculumCallback(curriculum, out / "curriculum.json", stage,
                                                history))
        t0 = time.perf_counter()
        # the first critic_warmup_steps fit the value function only (actor frozen), so that
        # a warm-started actor is not updated with a random critic's advantages
        warmup = min(max(config.critic_warmup_steps - start_steps, 0), max(remaining, 0))
        fresh = checkpoint is None
        interrupted = False
        # SIGTERM (a scheduler's stop, `kill`) ends the run as Ctrl-C does: what was learned
        # is saved; background jobs ignore SIGINT, so this is how they are stopped cleanly
        previous_term = signal.signal(signal.SIGTERM, _raise_interrupt)
        try:
            for steps, critic_only in ((warmup, True), (remaining - warmup, False)):
                if steps <= 0:
                    continue
                set_actor_trainable(model.policy, not critic_only)
                model.learn(steps, callback=callbacks, progress_bar=progress,
                            reset_num_timesteps=fresh, tb_log_name="ppo")
                fresh = False
        except KeyboardInterrupt:           # Ctrl-C: keep what was learned, say so
            interrupted = True
        except (EOFError, BrokenPipeError, ConnectionResetError) as err:
            error = worker_error(report_dir)
            if error is None:
                raise
            raise error from err
        finally:
            signal.signal(signal.SIGTERM, previous_term)
        set_actor_trainable(model.policy, True)
        wall = time.perf_counter() - t0
        save_model(model, out / "model.zip")
        if interrupted:                     # --resume continues from here
            save_model(model, out / "checkpoints" / f"ppo_{model.num_timesteps}_steps.zip")
        summary_path = out / "summary.json"
        sessions = previous_sessions(summary_path) + [{
            "from_step": int(start_steps), "to_step": int(model.num_timesteps),
            "wall_time_s": round(wall, 1),
            "env_steps_per_s": round((model.num_timesteps - start_steps) / max(wall, 1e-9), 1)}]
        total_wall = sum(s["wall_time_s"] for s in sessions)
        write_text_atomic(summary_path, json.dumps({
            "timesteps": int(model.num_timesteps), "wall_time_s": round(total_wall, 1),
            "env_steps_per_s": round(sum(s["to_step"] - s["from_step"] for s in sessions)
                                     / max(total_wall, 1e-9), 1),
            "sessions": sessions, "interrupted": interrupted}, indent=2))
        plot_learning_curve(out)
    finally:
        for vec in (env, eval_env):
            try:
                vec.close()
            except (EOFError, BrokenPipeError, ConnectionResetError):
                pass                        # workers already gone after Ctrl-C or an error
        shutil.rmtree(report_dir, ignore_errors=True)
    return model


def _benchmark(parser, config: TrainConfig, steps: int) -> int:
    """``--benchmark``: print the throughput table of ``config``."""
    from homing_gym.env import simulation_settings
    from homing_train.learning.throughput import measure, table

    if steps < config.ppo.get("n_steps", 2048) * config.n_envs:
        parser.error(f"--benchmark {steps}: at least one rollout is needed, n_steps x n_envs "
                     f"= {config.ppo.get('n_steps', 2048) * config.n_envs} steps")
    import torch

    sim = simulation_settings(config.env_kwargs)
    shape = config.env_kwargs.get("panorama_shape", "48x256")
    shape = "x".join(map(str, shape)) if isinstance(shape, (list, tuple)) else shape
    label = (f"{config.env_id.split('/')[-1]} {config.env_kwargs.get('scene', '')} {shape} "
             f"{sim['renderer']}, {config.extractor}, n_epochs {config.ppo.get('n_epochs')}, "
             f"batch {config.ppo.get('batch_size')}, {config.vec}"
             + (f" in {config.workers} workers" if config.vec != "dummy" and config.workers
                else ""))
    torch.set_num_threads(config.torch_threads)
    try:
        env = make_vec(config, config.n_envs, config.seed)
        try:
            env.action_space.seed(config.seed)
            check_memory(config, env.observation_space)
            model = new_model(config, env)
            if config.init_policy:      # a trained policy's episodes, not a random one's
                load_policy_weights(model, config.init_policy)
                label += f", from {Path(config.init_policy).name}"
            print(table([measure(env, model, steps, label)]))
        finally:
            env.close()
    except (ValueError, EnvWorkerError) as err:
        parser.exit(2, f"homing-train: error: {err}\n")
    return 0


def saved_config(run: Path, timesteps: int | None = None) -> TrainConfig:
    """The config of the run in folder ``run`` (its ``config.yml``, read as plain YAML
    data), with ``timesteps`` instead of its own if given; ``ValueError`` naming the file
    and the bad field otherwise."""
    path = run / "config.yml"
    if not path.is_file():
        raise ValueError(f"--resume {run}: no config.yml there (not a run folder)")
    try:
        saved = yaml.safe_load(path.read_text())
    except (OSError, UnicodeDecodeError, yaml.YAMLError) as err:
        raise ValueError(f"{path} is not readable YAML: {' '.join(str(err).split())}") from err
    names = [f.name for f in fields(TrainConfig)]
    if not isinstance(saved, dict):
        raise ValueError(f"{path} must map the run's settings {names}, got "
                         f"{type(saved).__name__}")
    unknown = sorted(str(key) for key in set(saved) - set(names))
    if unknown or "env_id" not in saved:
        raise ValueError(f"{path}: " + (f"unknown fields {unknown}; allowed: {names}"
                                        if unknown else "no env_id field"))
    try:
        return TrainConfig(**{**saved, **({"timesteps": timesteps} if timesteps else {})})
    except ValueError as err:
        raise ValueError(f"{path}: {err}") from err


def resume_checkpoint(run: Path, config: TrainConfig) -> Path:
    """The newest intact checkpoint of ``run``, saying on stderr which newer ones are torn
    and skipped; ``ValueError`` when there is none."""
    torn: list[tuple[Path, str]] = []
    checkpoint = latest_checkpoint(run, torn)
    for path, why in torn:
        print(f"homing-train: warning: skipping torn checkpoint {path} ({why})",
              file=sys.stderr)
    if checkpoint is None:             # starting over would overwrite model.zip
        raise ValueError(f"--resume {run}: no {'intact ' if torn else ''}checkpoint in "
                         f"{run / 'checkpoints'} to continue from (one is saved every "
                         f"checkpoint_freq = {config.checkpoint_freq} steps and when a run "
                         f"is interrupted); start a new run with another --out")
    return checkpoint


def resume_hint(run: Path) -> str:
    """How to continue ``run`` after a failure, when it has an intact checkpoint."""
    kept = latest_checkpoint(run)
    return (f"; the saves before it are whole: homing-train --resume {run} continues from "
            f"{kept.name}" if kept else "")


def starting_settings(parser, args) -> tuple[str, dict[str, Any]]:
    """The env id and settings ``--hp`` and the flags start from: ``--recipe``'s, else the
    hyperparameter file's for ``--env``."""
    if args.recipe is None:
        env_id = args.env or DEFAULT_ENV
        return env_id, load_hyperparams(env_id, args.hyperparams)
    if args.hyperparams != HYPERPARAMS:
        parser.error("--recipe and --hyperparams both give the starting settings: use one")
    env_id, settings = recipe(args.recipe)
    if args.env not in (None, env_id):
        raise ValueError(f"--recipe {args.recipe} trains {env_id}, not --env {args.env}")
    return env_id, settings


def main(argv: list[str] | None = None) -> int:
    parser = command_parser("homing-train", __doc__)
    parser.add_argument("--env", help="env id (default homing_gym/LocalHoming-v0, or the "
                        "recipe's)")
    parser.add_argument("--out", help="run folder (default runs/<env>_<extractor>_s<seed>)")
    parser.add_argument("--resume", metavar="RUN", help="continue the run in this folder "
                        "from its last checkpoint, with its saved config")
    parser.add_argument("--hyperparams", type=Path, default=HYPERPARAMS,
                        help="YAML file keyed by env id")
    parser.add_argument("--recipe", metavar="NAME",
                        help="start from the settings the policy NAME was trained with "
                             "(its env, envs, network, PPO settings, curriculum), e.g. "
                             "ppo_procedural_long, the default learned policy, or a policy "
                             "shipped before (ppo_procedural_fast); --hp and the flags "
                             "override them")
    parser.add_argument("--hp", action="append", default=[], metavar="KEY=VALUE",
                        help="override a hyperparameter (YAML value); repeatable")
    parser.add_argument("--env-kwargs", type=json.loads, help="JSON kwargs of gym.make")
    parser.add_argument("--seed", type=seed_value)
    parser.add_argument("--timesteps", type=int)
    parser.add_argument("--n-envs", type=int)
    parser.add_argument("--vec", choices=VECS,
                        help="how the envs run: 'subproc' (a process per env, or --workers "
                             "processes each stepping a group), 'dummy' (in turn, in this "
                             "process), 'native' (homing-gym's native vector env: this "
                             "process, panoramas rendered in threads, or --workers processes)")
    parser.add_argument("--workers", type=int,
                        help="processes that step the envs (--vec subproc or native)")
    parser.add_argument("--device")
    parser.add_argument("--extractor", choices=EXTRACTORS)
    parser.add_argument("--no-progress", action="store_true")
    parser.add_argument("--benchmark", type=int, metavar="STEPS", nargs="?", const=4096,
                        help="measure this configuration's throughput over STEPS env steps "
                             "(env alone, inference, PPO end to end and its rollout/update "
                             "split; default 4096) and print it; trains nothing, writes "
                             "nothing. With --hp init_policy=ZIP, PPO starts from that "
                             "network (a trained policy's episodes: longer, fewer resets)")
    args = parser.parse_args(argv)
    try:
        require_extra("train", "homing-train")
    except MissingExtraError as err:
        parser.exit(2, f"homing-train: error: {err}\n")
    if args.resume is not None and args.recipe:
        parser.error("--resume continues a run with its saved config; --recipe starts a new "
                     "one: use one")
    if args.resume is not None and args.out is not None:
        parser.error("--resume continues the run in its own folder; --out is not used with it")
    try:
        if args.resume is not None:
            run = Path(checked_output_dir(args.resume, "--resume"))
            config = saved_config(run, args.timesteps)
        else:
            env_id, settings = starting_settings(parser, args)
            settings.update(parse_overrides(args.hp))
            start = settings.get("init_policy")
            if args.recipe and start and not Path(start).is_file():
                raise ValueError(f"--recipe {args.recipe} starts from init_policy {start!r}, "
                                 f"a file of the machine that trained it, not here: give one "
                                 f"with --hp init_policy=ZIP, or start from scratch with --hp "
                                 f"init_policy=null")
            config = make_config(env_id, settings, seed=args.seed, timesteps=args.timesteps,
                                 n_envs=args.n_envs, vec=args.vec, workers=args.workers,
                                 device=args.device,
                                 extractor=args.extractor, env_kwargs=args.env_kwargs)
            if args.benchmark is None:
                run = Path(checked_output_dir(
                    f"runs/{config.env_id.split('/')[-1]}_{config.extractor}_s{config.seed}"
                    if args.out is None else args.out, "--out"))
    except ValueError as err:
        parser.error(str(err))
    if args.benchmark is not None:
        return _benchmark(parser, config, args.benchmark)
    try:
        with OutputLock(run):           # a second homing-train on this folder is refused
            if args.resume is not None:
                resume_checkpoint(run, config)
            elif run.is_dir() and any(run.iterdir()):
                raise ValueError(f"--out {run} already holds files (an earlier run?): "
                                 f"continue it with --resume {run}, or choose another --out")
            train(config, run, resume=args.resume is not None, progress=not args.no_progress)
    except (ValueError, EnvWorkerError) as err:
        parser.exit(2, f"homing-train: error: {err}\n")
    except OSError as err:          # a full disk, say: every save made before it is whole
        parser.exit(1, f"homing-train: error: {err}{resume_hint(run)}\n")
    except KeyboardInterrupt:       # outside learn() (which keeps its work): in a save, say
        parser.exit(130, f"homing-train: interrupted{resume_hint(run)}\n")
    summary = json.loads((run / "summary.json").read_text())
    if summary.get("interrupted"):
        print(f"interrupted at step {summary['timesteps']}: model.zip, a checkpoint and "
              f"summary.json are saved; homing-train --resume {run} continues")
        return 130
    print(f"run folder: {run} ({summary})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
