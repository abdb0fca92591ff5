"""The stable-baselines3 PPO arguments that a ``homing-train`` run may set (``ppo.yml`` or
``--hp KEY=VALUE``), checked value by value before any env or network is built, and
turned into PPO's constructor arguments.

Schedules: ``learning_rate`` and ``clip_range`` take a number or ``"lin_X"`` (decays
linearly from X to 0 over the run, rl-baselines3-zoo's notation). ``policy_kwargs`` takes
:data:`POLICY_KEYS`; the features extractor is the run's ``extractor``/``features_dim``,
not a policy keyword.
"""

from __future__ import annotations

import math
from typing import Any, Callable

#: PPO constructor arguments a run may set.
PPO_KEYS = ("n_steps", "batch_size", "n_epochs", "learning_rate", "gamma", "gae_lambda",
            "clip_range", "clip_range_vf", "normalize_advantage", "ent_coef", "vf_coef",
            "max_grad_norm", "target_kl", "use_sde", "sde_sample_freq", "policy_kwargs")
#: ``policy_kwargs`` keys a run may set.
POLICY_KEYS = ("net_arch", "activation_fn", "ortho_init", "log_std_init",
               "share_features_extractor")
#: ``activation_fn`` names and their ``torch.nn`` classes.
ACTIVATIONS = {"tanh": "Tanh", "relu": "ReLU", "elu": "ELU", "leaky_relu": "LeakyReLU",
               "gelu": "GELU", "silu": "SiLU"}
SCHEDULED = ("learning_rate", "clip_range")


def _number(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool) \
        and math.isfinite(value)


def _integer(value: Any, least: int) -> bool:
    return isinstance(value, int) and not isinstance(value, bool) and value >= least


def schedule_start(value: Any) -> float | None:
    """The number of a constant or the start of a ``"lin_X"`` schedule; None if neither."""
    if isinstance(value, str) and value.startswith("lin_"):
        try:
            value = float(value[4:])
        except ValueError:
            return None
    return float(value) if _number(value) else None


#: key -> (test of the value, what is allowed)
RULES: dict[str, tuple[Callable[[Any], bool], str]] = {
    "n_steps": (lambda v: _integer(v, 2), "an integer >= 2 (steps per env per rollout)"),
    "batch_size": (lambda v: _integer(v, 2), "an integer >= 2"),
    "n_epochs": (lambda v: _integer(v, 1), "an integer >= 1"),
    "learning_rate": (lambda v: (schedule_start(v) or 0) > 0,
                      "a positive number or 'lin_X' (X > 0, decays linearly to 0)"),
    "gamma": (lambda v: _number(v) and 0 < v <= 1, "a number in (0, 1]"),
    "gae_lambda": (lambda v: _number(v) and 0 <= v <= 1, "a number in [0, 1]"),
    "clip_range": (lambda v: (schedule_start(v) or 0) > 0,
                   "a positive number or 'lin_X' (X > 0, decays linearly to 0)"),
    "clip_range_vf": (lambda v: v is None or (_number(v) and v > 0),
                      "null (no value clipping) or a positive number"),
    "normalize_advantage": (lambda v: isinstance(v, bool), "true or false"),
    "ent_coef": (lambda v: _number(v) and v >= 0, "a number >= 0"),
    "vf_coef": (lambda v: _number(v) and v >= 0, "a number >= 0"),
    "max_grad_norm": (lambda v: _number(v) and v > 0, "a positive number"),
    "target_kl": (lambda v: v is None or (_number(v) and v > 0),
                  "null (no early stop) or a positive number"),
    "use_sde": (lambda v: isinstance(v, bool), "true or false (continuous actions only)"),
    "sde_sample_freq": (lambda v: _integer(v, -1), "an integer >= -1"),
}
POLICY_RULES: dict[str, tuple[Callable[[Any], bool], str]] = {
    "net_arch": (lambda v: _layers(v) or (isinstance(v, dict) and set(v) == {"pi", "vf"}
                                          and all(_layers(x) for x in v.values())),
                 "a list of layer widths, e.g. [64, 64], or {pi: [...], vf: [...]}"),
    "activation_fn": (lambda v: v in ACTIVATIONS, f"one of {list(ACTIVATIONS)}"),
    "ortho_init": (lambda v: isinstance(v, bool), "true or false"),
    "log_std_init": (_number, "a number"),
    "share_features_extractor": (lambda v: isinstance(v, bool), "true or false"),
}


def _layers(value: Any) -> bool:
    return isinstance(value, list) and all(_integer(x, 1) for x in value)


def _convolutions(value: Any) -> bool:
    return isinstance(value, (list, tuple)) and len(value) >= 1 and all(
        isinstance(layer, (list, tuple)) and len(layer) == 3
        and all(_integer(x, 1) for x in layer) for layer in value)


_CONVOLUTIONS = ("a non-empty list of [channels, kernel, stride] layers of integers >= 1, "
                 "e.g. [[16, 5, 1], [16, 5, 1]]")
#: extractor -> its keyword arguments a run may set (``extractor_kwargs``; ``features_dim``
#: is a setting of its own) -> (test of the value, what is allowed).
EXTRACTOR_RULES: dict[str, dict[str, tuple[Callable[[Any], bool], str]]] = {
    "panorama": {"layers": (_convolutions, _CONVOLUTIONS)},
    "band": {"layers": (_convolutions, _CONVOLUTIONS)},
    "align": {"encoder": (lambda v: _convolutions(v) and all(s == 1 for _, _, s in v),
                          _CONVOLUTIONS + " with strides 1 (one column per shift)"),
              "head": (_convolutions, _CONVOLUTIONS),
              "temperature": (lambda v: _number(v) and v > 0, "a positive number")},
    "combined": {},
}


def extractor_arguments(extractor: str, kwargs: Any) -> dict[str, Any]:
    """``kwargs`` (``extractor_kwargs`` of a run) checked against :data:`EXTRACTOR_RULES`
    and made into the extractor's arguments (layer lists become tuples); raises
    ``ValueError`` naming every unknown key and bad value."""
    rules = EXTRACTOR_RULES[extractor]
    if not isinstance(kwargs, dict):
        raise ValueError(f"extractor_kwargs must be a mapping of {list(rules)} (the "
                         f"{extractor!r} extractor's settings), got {kwargs!r}")
    unknown = sorted(set(kwargs) - set(rules))
    bad = [f"unknown extractor_kwargs {unknown} for the {extractor!r} extractor; allowed: "
           f"{list(rules)}"] if unknown else []
    bad += [f"extractor_kwargs.{key} must be {rule}, got {kwargs[key]!r}"
            for key, (ok, rule) in rules.items() if key in kwargs and not ok(kwargs[key])]
    if bad:
        raise ValueError("; ".join(bad))
    return {key: tuple(tuple(layer) for layer in value) if isinstance(value, (list, tuple))
            else float(value) for key, value in kwargs.items()}


def check_ppo(ppo: dict[str, Any], n_envs: int) -> None:
    """Raise ``ValueError`` naming every unknown key and bad value of ``ppo`` (and a
    ``batch_size`` larger than one rollout, ``n_steps * n_envs``)."""
    unknown = sorted(set(ppo) - set(PPO_KEYS))
    if unknown:
        raise ValueError(f"unknown PPO hyperparameters {unknown}; allowed: {list(PPO_KEYS)}")
    bad = [f"{key} must be {rule}, got {ppo[key]!r}"
           for key, (ok, rule) in RULES.items() if key in ppo and not ok(ppo[key])]
    kwargs = ppo.get("policy_kwargs", {})
    if not isinstance(kwargs, dict):
        bad.append(f"policy_kwargs must be a mapping of {list(POLICY_KEYS)}, got {kwargs!r}")
        kwargs = {}
    odd = sorted(set(kwargs) - set(POLICY_KEYS))
    if odd:
        bad.append(f"unknown policy_kwargs {odd}; allowed: {list(POLICY_KEYS)} (the features "
                   f"extractor is set by extractor and features_dim)")
    bad += [f"policy_kwargs.{key} must be {rule}, got {kwargs[key]!r}"
            for key, (ok, rule) in POLICY_RULES.items() if key in kwargs and not ok(kwargs[key])]
    if not bad and ppo.get("batch_size", 64) > ppo.get("n_steps", 2048) * n_envs:
        bad.append(f"batch_size ({ppo.get('batch_size', 64)}) must be at most one rollout, "
                   f"n_steps x n_envs = {ppo.get('n_steps', 2048) * n_envs}")
    if bad:
        raise ValueError("PPO settings: " + "; ".join(bad))


def ppo_arguments(ppo: dict[str, Any]) -> dict[str, Any]:
    """``ppo`` (checked by :func:`check_ppo`) as PPO constructor arguments: ``"lin_X"``
    schedules become stable-baselines3 linear schedules, activation names ``torch.nn``
    classes; ``policy_kwargs`` is returned apart, to be merged with the extractor's."""
    import torch
    from stable_baselines3.common.utils import LinearSchedule

    out = {k: v for k, v in ppo.items() if k != "policy_kwargs"}
    for key in SCHEDULED:
        if isinstance(out.get(key), str):
            out[key] = LinearSchedule(schedule_start(out[key]), 0.0, 1.0)
    policy = dict(ppo.get("policy_kwargs", {}))
    if "activation_fn" in policy:
        policy["activation_fn"] = getattr(torch.nn, ACTIVATIONS[policy["activation_fn"]])
    out["policy_kwargs"] = policy
    return out


def check_device(device: str) -> None:
    """Raise ``ValueError`` unless ``device`` is ``"auto"`` or a torch device this machine
    has. SB3 alone would quietly train on the CPU when ``"cuda"`` is asked for and torch
    sees no GPU, and fail deep inside torch on a misspelt name."""
    import torch

    if device == "auto":
        return
    try:
        kind = torch.device(device).type
    except (RuntimeError, TypeError):
        raise ValueError(f"device {device!r} is not a torch device; use 'cpu', 'cuda', "
                         f"'cuda:N', 'mps' or 'auto'") from None
    available = {"cpu": True, "cuda": torch.cuda.is_available(),
                 "mps": torch.backends.mps.is_available()}
    if not available.get(kind, False):
        raise ValueError(f"device {device!r}: torch {torch.__version__} sees no such device "
                         f"on this machine (a CPU-only build?); use 'cpu' or 'auto'")
