"""Read a stable-baselines3 PPO zip without unpickling anything from it.

``PPO.load`` unpickles several entries of the zip's ``data`` JSON (the policy class, the
spaces, ``policy_kwargs``, schedules), so loading a file from someone else runs code of
their choosing. :func:`load_policy` reads only what can be read as data:

* the policy class, matched by its stored docstring against an allow-list of SB3's
  actor-critic policies;
* the observation and action spaces, parsed from their stored ``repr`` text
  (``Dict``, ``Box`` and ``Discrete`` only);
* ``policy_kwargs``: the features extractor matched *by class name* against an allow-list
  (this package's extractors and SB3's own), every other entry parsed with
  :func:`ast.literal_eval`;
* the weights from ``policy.pth`` with ``torch.load(weights_only=True)``.

Anything else raises :class:`UntrustedPolicyError`; ``trust=True`` (the ``--trust-policy``
flag of the tools) falls back to ``PPO.load``, which runs code from the file.
"""

from __future__ import annotations

import ast
import io
import json
import re
import zipfile
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from gymnasium import spaces


class UntrustedPolicyError(ValueError):
    """The zip needs unpickling to load; only ``trust=True`` may do that."""


@dataclass
class LoadedPolicy:
    """A policy network and the spaces it was trained on."""

    policy: Any                       # an SB3 ActorCriticPolicy, in eval mode
    observation_space: spaces.Space
    action_space: spaces.Space

    def predict(self, observation, state=None, episode_start=None, deterministic=True):
        """SB3's ``predict``: ``(action, state)``."""
        return self.policy.predict(observation, state=state, episode_start=episode_start,
                                   deterministic=deterministic)


def _policy_classes() -> dict[str, type]:
    from stable_baselines3.common.policies import (ActorCriticCnnPolicy, ActorCriticPolicy,
                                                   MultiInputActorCriticPolicy)
    return {cls.__doc__: cls for cls in (ActorCriticPolicy, ActorCriticCnnPolicy,
                                         MultiInputActorCriticPolicy)}


def _extractor_classes() -> dict[str, type]:
    from stable_baselines3.common import torch_layers

    from homing_train.learning import extractor
    known = [extractor.PanoramaGoalExtractor, extractor.HorizonBandExtractor,
             extractor.AlignedBandExtractor,
             torch_layers.CombinedExtractor,
             torch_layers.NatureCNN, torch_layers.FlattenExtractor]
    return {cls.__name__: cls for cls in known}


def _activation_classes() -> dict[str, type]:
    from torch import nn
    return {cls.__name__: cls for cls in (nn.Tanh, nn.ReLU, nn.ELU, nn.LeakyReLU, nn.GELU,
                                          nn.SiLU)}


_CLASS = re.compile(r"^<class '([\w.]+)'>$")
_BOX = re.compile(r"Box\((\[[^\]]*\]|[^,]+), (\[[^\]]*\]|[^,]+), \(([\d, ]*)\), (\w+)\)")


def _class_by_name(text: str, allowed: dict[str, type], what: str, path: str) -> type:
    match = _CLASS.match(text.strip())
    name = match.group(1).rsplit(".", 1)[-1] if match else None
    if name not in allowed:
        raise UntrustedPolicyError(
            f"{path}: {what} {text!r} is not one of the known classes {sorted(allowed)}; "
            f"loading it would unpickle code from the file (pass --trust-policy to allow)")
    return allowed[name]


def _number_array(text: str) -> np.ndarray:
    return np.array([float(v) for v in text.strip("[] ").split()], dtype=np.float64)


def _box(match: re.Match) -> spaces.Box:
    low, high, shape, dtype = match.groups()[-4:]
    shape_t = tuple(int(v) for v in shape.replace(" ", "").split(",") if v)
    dtype_np = np.dtype(dtype)
    low_v = _number_array(low) if low.startswith("[") else float(low)
    high_v = _number_array(high) if high.startswith("[") else float(high)
    return spaces.Box(low_v, high_v, shape_t, dtype_np)


def _space(entry: dict, path: str) -> spaces.Space:
    kind = entry.get(":type:", "")
    if "spaces.dict.Dict" in kind:
        text = entry.get("spaces", "")
        members = {m.group(1): _box(m) for m in re.finditer(r"'(\w+)': " + _BOX.pattern, text)}
        if not members or len(members) != text.count("': "):
            raise UntrustedPolicyError(f"{path}: cannot read the Dict observation space "
                                       f"{text!r} without unpickling (only Box members)")
        return spaces.Dict(members)
    if "spaces.box.Box" in kind:
        shape = entry["_shape"]
        shape = tuple(ast.literal_eval(shape) if isinstance(shape, str) else shape)
        low = _number_array(str(entry.get("low_repr") or entry.get("low", "")))
        high = _number_array(str(entry.get("high_repr") or entry.get("high", "")))
        return spaces.Box(low.reshape(shape) if low.size > 1 else float(low[0]),
                          high.reshape(shape) if high.size > 1 else float(high[0]), shape,
                          np.dtype(entry["dtype"]))
    if "spaces.discrete.Discrete" in kind:
        return spaces.Discrete(int(entry["n"]), start=int(entry.get("start", 0)))
    raise UntrustedPolicyError(f"{path}: space of type {kind!r} cannot be read without "
                               f"unpickling (pass --trust-policy to allow)")


def _policy_kwargs(entry: dict | None, path: str) -> dict[str, Any]:
    if not entry:
        return {}
    out: dict[str, Any] = {}
    for key, text in entry.items():
        if key.startswith(":"):
            continue
        if key == "features_extractor_class":
            out[key] = _class_by_name(text, _extractor_classes(), "features extractor", path)
        elif not isinstance(text, str):     # stored as JSON: plain data already
            out[key] = text
        elif key == "activation_fn":
            out[key] = _class_by_name(text, _activation_classes(), "activation", path)
        else:
            try:
                out[key] = ast.literal_eval(text)
            except (ValueError, SyntaxError):
                raise UntrustedPolicyError(
                    f"{path}: policy_kwargs[{key!r}] = {text!r} is not plain data (pass "
                    f"--trust-policy to unpickle it)") from None
    return out


def _read_zip(path: str) -> tuple[dict, bytes]:
    try:
        with zipfile.ZipFile(path) as archive:
            data = json.loads(archive.read("data"))
            weights = archive.read("policy.pth")
    except FileNotFoundError:
        raise ValueError(f"policy file {path!r} does not exist") from None
    except (zipfile.BadZipFile, KeyError, json.JSONDecodeError, OSError) as err:
        raise ValueError(f"{path}: not a stable-baselines3 model zip ({err})") from None
    return data, weights


def load_policy(path: str | Path, trust: bool = False) -> LoadedPolicy:
    """The policy network saved in the SB3 PPO zip at ``path``, on the CPU, read without
    unpickling (see the module docstring); ``trust=True`` uses ``PPO.load`` instead."""
    import torch

    path = str(path)
    if trust:
        from stable_baselines3 import PPO
        model = PPO.load(path, device="cpu")
        return LoadedPolicy(model.policy, model.observation_space, model.action_space)
    data, weights = _read_zip(path)
    try:
        stored_doc = data["policy_class"]["__doc__"]
        observation_space = _space(data["observation_space"], path)
        action_space = _space(data["action_space"], path)
    except (KeyError, TypeError) as err:
        raise ValueError(f"{path}: model data lacks {err}") from None
    policy_class = _policy_classes().get(stored_doc)
    if policy_class is None:
        raise UntrustedPolicyError(f"{path}: the policy class is not one of SB3's actor-critic "
                                   f"policies (pass --trust-policy to unpickle it)")
    kwargs = _policy_kwargs(data.get("policy_kwargs"), path)
    policy = policy_class(observation_space, action_space, lambda _: 0.0, **kwargs)
    try:
        state = torch.load(io.BytesIO(weights), map_location="cpu", weights_only=True)
        policy.load_state_dict(state)
    except Exception as err:  # torch raises many types for a bad or mismatched file
        raise ValueError(f"{path}: policy weights do not load ({type(err).__name__}: "
                         f"{err})") from None
    policy.set_training_mode(False)
    return LoadedPolicy(policy, observation_space, action_space)
