"""What the harness evaluates: a registered controller (with parameters) or an SB3 model.

:class:`PolicySpec` is a small picklable description that every worker process turns
into a live policy with :meth:`PolicySpec.build`; :func:`parse_params` reads the
``--param key=value`` overrides of the command line.
"""

from __future__ import annotations

import dataclasses
import json
import os
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np
from gymnasium import spaces

import homing_baselines
from homing_baselines import Controller

#: Parameters of SB3 models and their defaults; ``trust=True`` unpickles the zip (runs code
#: from the file, see :mod:`homing_train.learning.policy_zip`).
SB3_PARAMS: dict[str, Any] = {"deterministic": True, "trust": False}


#: The model files every ``homing-train`` run writes (named by their run folder in results).
RUN_MODEL_NAMES = ("model", "best_model")


@dataclass
class PolicySpec:
    """``kind`` is ``"controller"`` (``source`` = registry name, ``params`` overrides,
    or a ready ``instance``) or ``"sb3"`` (``source`` = path of a model zip)."""

    kind: str
    source: str
    params: dict[str, Any] = field(default_factory=dict)
    instance: Controller | None = None

    @property
    def label(self) -> str:
        """Name used in results and plots: a controller's name, a zip's file name without
        ``.zip``, led by its run folder's name where the file is one every run writes
        (``runs/abc/model.zip`` -> ``abc/model``, ``runs/abc/checkpoints/ppo_8_steps.zip``
        -> ``abc/ppo_8_steps``)."""
        if self.kind != "sb3":
            return self.source
        path = Path(self.source)
        checkpoint = path.parent.name == "checkpoints"
        run = (path.parent.parent if checkpoint else path.parent).name
        generic = checkpoint or path.stem in RUN_MODEL_NAMES
        return f"{run}/{path.stem}" if generic and run else path.stem

    @property
    def sequential(self) -> bool:
        """Whether its episodes must run in order in one process (a controller that keeps
        a memory across episodes, :meth:`Controller.keeps_memory_across_episodes`)."""
        return self.kind == "controller" and self.build().keeps_memory_across_episodes()

    def build(self):
        """A fresh live policy (in the calling process)."""
        if self.kind == "sb3":
            return SB3Policy(self.source, **self.params)
        if self.instance is not None:
            return dataclasses.replace(self.instance)
        return homing_baselines.make(self.source, **self.params)

    def resolved_params(self) -> dict[str, Any]:
        """All parameter values of a controller (defaults included); the path for SB3."""
        if self.kind == "sb3":
            return {"path": os.path.abspath(self.source), **SB3_PARAMS, **self.params}
        return (self.instance if self.instance is not None else self.build()).params()


@dataclass(frozen=True)
class RecordedSettings:
    """How a policy zip is evaluated, from the ``.yml`` beside it (written by
    ``homing_train.learning.ship``): ``env_kwargs`` (``eval_env_kwargs``), ``params``
    (``eval_params``, e.g. ``{"deterministic": False}``) and the ``env_id`` it was trained
    on, or from its run folder's ``config.yml`` (no params); ``source`` the file read,
    ``None`` when there is none; ``privileged``: what beyond pixels its training used
    ("" if nothing: :func:`privileged_training`)."""

    env_kwargs: dict[str, Any] = field(default_factory=dict)
    params: dict[str, Any] = field(default_factory=dict)
    env_id: str | None = None
    source: str | None = None
    privileged: str = ""


#: What a warm start from the ``oracle`` (pose pairs or DAgger) gives a policy beyond pixels.
ORACLE_DEMONSTRATIONS = "oracle demonstrations (true poses) in training"


def privileged_training(config: dict[str, Any]) -> str:
    """What beyond pixels a ``homing-train`` run with ``config`` (its ``config.yml``)
    trained on: :data:`ORACLE_DEMONSTRATIONS` with a pose-pair or DAgger warm start, else
    "" (a run started from another's network, ``init_policy``, is not traced)."""
    warm = config.get("pretrain_samples") or config.get("imitation_iterations")
    return ORACLE_DEMONSTRATIONS if warm else ""


def eval_env_kwargs(train_env_kwargs: dict[str, Any]) -> dict[str, Any]:
    """The env kwargs a policy trained with ``train_env_kwargs`` is evaluated with: all but
    the training ``scene``, so that the evaluation's own scene applies."""
    return {k: v for k, v in train_env_kwargs.items() if k != "scene"}


#: The largest settings file read beside a policy zip (a run's ``config.yml``, a ``.yml``).
MAX_SETTINGS_BYTES = 2**20
#: The fields read from a run's ``config.yml`` and from a shipped policy's ``.yml``, with
#: their types (each may be absent or null).
RUN_CONFIG_FIELDS = {"env_id": str, "env_kwargs": dict, "eval_deterministic": bool,
                     "pretrain_samples": int, "imitation_iterations": int}
SHIPPED_FIELDS = {"env_id": str, "eval_env_kwargs": dict, "eval_params": dict,
                  "privileged": str}
_KINDS = {str: "a text", dict: "a mapping with text keys", bool: "true or false",
          int: "an integer >= 0"}


def _settings_file(path: str, fields: dict[str, type]) -> dict[str, Any]:
    """The settings mapping in the YAML file ``path`` (read with ``yaml.safe_load``; an
    empty file is ``{}``), its ``fields`` checked for their types; ``ValueError`` naming
    the file and the field otherwise."""
    import yaml

    try:
        size = os.path.getsize(path)
        if size > MAX_SETTINGS_BYTES:
            raise ValueError(f"{path}: {size:,} bytes, more than the {MAX_SETTINGS_BYTES:,} "
                             f"a settings file may have")
        with open(path, encoding="utf-8") as file:
            settings = yaml.safe_load(file)
    except (OSError, UnicodeDecodeError, yaml.YAMLError) as err:
        raise ValueError(f"{path}: not readable YAML ({' '.join(str(err).split())})") from None
    if settings is None:
        return {}
    if not isinstance(settings, dict):
        raise ValueError(f"{path}: must map settings to values, got "
                         f"{type(settings).__name__}")
    for key, kind in fields.items():
        value = settings.get(key)
        ok = value is None or (isinstance(value, kind)
                               and (kind is bool or not isinstance(value, bool))
                               and (kind is not int or value >= 0)
                               and (kind is not dict or all(isinstance(k, str) for k in value)))
        if not ok:
            raise ValueError(f"{path}: {key} must be {_KINDS[kind]}, got {value!r:.80}")
    return settings


def recorded_settings(zip_path: str) -> RecordedSettings:
    """The evaluation settings recorded beside the policy zip ``zip_path``: its ``.yml``
    (a shipped policy), else the ``config.yml`` of the ``homing-train`` run folder it lies
    in, directly or in its ``checkpoints/`` (:func:`eval_env_kwargs` of the training env
    kwargs; sampled actions if the run's evaluations sampled them). ``ValueError`` naming
    the file and the field if the file is not such settings (:func:`_settings_file`)."""
    meta_path = os.path.splitext(zip_path)[0] + ".yml"
    folder = os.path.dirname(zip_path)
    if os.path.basename(folder) == "checkpoints":
        folder = os.path.dirname(folder)
    run_config = os.path.join(folder, "config.yml")
    if not os.path.isfile(meta_path) and os.path.isfile(run_config):
        config = _settings_file(run_config, RUN_CONFIG_FIELDS)
        params = ({"deterministic": False} if config.get("eval_deterministic") is False
                  else {})
        return RecordedSettings(eval_env_kwargs(dict(config.get("env_kwargs") or {})), params,
                                config.get("env_id"), run_config, privileged_training(config))
    if not os.path.isfile(meta_path):
        return RecordedSettings()
    meta = _settings_file(meta_path, SHIPPED_FIELDS)
    return RecordedSettings(dict(meta.get("eval_env_kwargs") or {}),
                            dict(meta.get("eval_params") or {}), meta.get("env_id"), meta_path,
                            str(meta.get("privileged") or ""))


def policy_spec(policy: str | Controller | PolicySpec,
                params: dict[str, Any] | None = None) -> PolicySpec:
    """Interpret ``policy``: a :class:`PolicySpec`, a controller instance, a registered
    controller name, a shipped policy's name (``ppo``: :data:`DEFAULT_POLICY`) or the
    path of a stable-baselines3 ``.zip``."""
    params = dict(params or {})
    if isinstance(policy, PolicySpec):
        return policy
    if isinstance(policy, Controller):
        if params:
            raise ValueError("give parameters to the controller instance, not as params")
        return PolicySpec("controller", policy.name or type(policy).__name__, {}, policy)
    if not isinstance(policy, str):
        raise ValueError(f"policy must be a controller name, a controller or a model zip "
                         f"path, got {policy!r}")
    if policy in homing_baselines.available():
        homing_baselines.make(policy, **params)  # validates the parameters now
        return PolicySpec("controller", policy, params)
    policy = shipped_policy_path(policy) or policy
    if policy.endswith(".zip") or os.path.exists(policy):
        if not os.path.isfile(policy):
            raise ValueError(f"model file {policy!r} does not exist")
        unknown = sorted(set(params) - set(SB3_PARAMS))
        if unknown:
            raise ValueError(f"SB3 models take the parameters {list(SB3_PARAMS)}, "
                             f"not {unknown}")
        for key in SB3_PARAMS:
            if not isinstance(params.get(key, SB3_PARAMS[key]), bool):
                raise ValueError(f"{key} must be true or false, got {params[key]!r}")
        return PolicySpec("sb3", policy, params)
    raise ValueError(f"unknown policy {policy!r}: not a registered controller "
                     f"{homing_baselines.available()}, a shipped policy "
                     f"{['ppo', *shipped_policy_names()]} nor a stable-baselines3 model .zip "
                     f"file")


def _coerce(text: str, default: Any, key: str) -> Any:
    """Parse ``text`` to the type of the parameter's default value."""
    try:
        if isinstance(default, bool):
            if text.lower() in ("true", "1", "yes"):
                return True
            if text.lower() in ("false", "0", "no"):
                return False
            raise ValueError
        if isinstance(default, int):
            return int(text)
        if isinstance(default, float):
            return float(text)
        if isinstance(default, str):
            return text
        return json.loads(text)
    except ValueError:
        raise ValueError(f"--param {key}={text!r}: expected a value of type "
                         f"{type(default).__name__}") from None


def parse_params(items: list[str] | None, controller: str) -> dict[str, Any]:
    """``["key=value", ...]`` -> typed parameter overrides for ``controller`` (a registered
    name, or an SB3 model path: then only :data:`SB3_PARAMS`)."""
    if not items:
        return {}
    if controller in homing_baselines.available():
        defaults = homing_baselines.parameters(controller)
    elif controller.endswith(".zip"):
        defaults = SB3_PARAMS
    else:
        raise ValueError("--param applies to registered controllers "
                         f"{homing_baselines.available()} and SB3 model .zip files")
    out: dict[str, Any] = {}
    for item in items:
        key, sep, value = item.partition("=")
        key = key.strip()
        if not sep or not key:
            raise ValueError(f"malformed --param {item!r}: expected key=value")
        if key not in defaults:
            raise ValueError(f"controller {controller!r} has no parameter {key!r}; "
                             f"parameters: {sorted(defaults)}")
        out[key] = _coerce(value.strip(), defaults[key], key)
    return out


def _spaces_match(model_space, env_space) -> bool:
    """Equal spaces, allowing the channel-first images SB3 stores for HWC image inputs."""
    if isinstance(model_space, spaces.Dict) and isinstance(env_space, spaces.Dict):
        return (set(model_space.spaces) == set(env_space.spaces)
                and all(_spaces_match(model_space[k], env_space[k]) for k in env_space.spaces))
    if isinstance(model_space, spaces.Box) and isinstance(env_space, spaces.Box):
        shape = env_space.shape
        transposed = (shape[-1], *shape[:-1]) if len(shape) == 3 else shape
        return model_space.dtype == env_space.dtype and model_space.shape in (shape, transposed)
    return model_space == env_space


class SB3Policy:
    """A stable-baselines3 PPO model behind the harness' policy interface.

    The zip is read without unpickling unless ``trust=True``
    (:mod:`homing_train.learning.policy_zip`).
    ``deterministic=True`` (default) acts with the mode of the action distribution;
    ``False`` samples from it, with torch's generator seeded by the episode seed at each
    :meth:`reset`, so a stochastic evaluation is reproducible episode by episode, whichever
    worker runs it."""

    def __init__(self, path: str, deterministic: bool = True, trust: bool = False):
        import torch

        # heavy imports: only when a model is evaluated
        from homing_train.learning.policy_zip import load_policy

        # one observation at a time: a thread pool only spins against the other workers
        torch.set_num_threads(1)
        self.path = path
        self.deterministic = bool(deterministic)
        self.model = load_policy(path, trust=trust)

    def check_env(self, env) -> None:
        """``ValueError`` if the model was trained on other observation or action spaces."""
        for what in ("observation_space", "action_space"):
            mine, theirs = getattr(self.model, what), getattr(env, what)
            if not _spaces_match(mine, theirs):
                raise ValueError(f"model {self.path!r} expects {what} {mine}, the env has "
                                 f"{theirs}; pass matching --env-kwargs (obs_keys, "
                                 f"action_type, panorama_shape)")

    def reset(self, seed: int | None = None) -> None:
        """No episode memory outside ``state``; seeds the action sampling."""
        if seed is not None and not self.deterministic:
            import torch

            torch.manual_seed(seed)

    def predict(self, observation, state=None, episode_start=None, deterministic=None):
        """The model's action; ``deterministic=None`` uses the policy's own setting."""
        start = None if episode_start is None else np.atleast_1d(episode_start)
        mode = self.deterministic if deterministic is None else deterministic
        return self.model.predict(observation, state=state, episode_start=start,
                                  deterministic=mode)


POLICY_DIR = Path(str(resources.files("homing_train") / "shipped"))
#: The default learned policy, which ``--policy ppo`` names.
DEFAULT_POLICY = "ppo_procedural_long"


def resolved_name(method: str) -> str:
    """``method`` with the alias ``"ppo"`` replaced by :data:`DEFAULT_POLICY`."""
    return DEFAULT_POLICY if method == "ppo" else method


def shipped_policy_names() -> list[str]:
    """The names of the shipped policies (their zips in :data:`POLICY_DIR`)."""
    return sorted(p.stem for p in POLICY_DIR.glob("*.zip"))


def shipped_policy_path(name: str) -> str | None:
    """The zip of the shipped policy ``name`` (``"ppo"``: :data:`DEFAULT_POLICY`), or
    ``None`` when no shipped policy has that name."""
    name = resolved_name(name)
    return str(POLICY_DIR / f"{name}.zip") if name in shipped_policy_names() else None


@dataclass(frozen=True)
class ShippedPolicy:
    """A shipped model and how it is evaluated (from the ``.yml`` beside it)."""

    path: Path
    env_kwargs: dict
    params: dict    # SB3 policy parameters, e.g. {"deterministic": False}
    env_id: str | None = None   # the env it was trained on (None: any)
    privileged: str = ""        # what beyond pixels its training used ("" if nothing)


def model_policy(model: Path) -> ShippedPolicy:
    """The PPO zip ``model`` with the evaluation settings recorded beside it
    (:func:`recorded_settings`: a shipped policy's ``.yml``, a run folder's config)."""
    settings = recorded_settings(str(model))
    return ShippedPolicy(Path(model), settings.env_kwargs, settings.params, settings.env_id,
                         settings.privileged)


def model_zips(methods: list[str] | None) -> dict[str, ShippedPolicy]:
    """The methods among ``methods`` that name an existing ``.zip`` file, as policies."""
    return {m: model_policy(Path(m)) for m in methods or []
            if m.endswith(".zip") and os.path.isfile(m)}


def shipped_policies(folder: Path = POLICY_DIR) -> dict[str, ShippedPolicy]:
    """Shipped PPO policies by name, with their recorded evaluation settings
    (:func:`recorded_settings`)."""
    return {model.stem: model_policy(model) for model in sorted(folder.glob("*.zip"))}
