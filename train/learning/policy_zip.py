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

Every size the file declares is checked, once, before anything is allocated
(:class:`PolicyFileError` names the file, the field and the bound): the zip's directory
and members (the ``MAX_*`` constants below), the spaces' shapes, dtypes and bytes, and the
network's parameters and activations, counted on torch's ``meta`` device
(:func:`checked_network`, which training can use on its own ``policy_kwargs``).
"""

from __future__ import annotations

import ast
import base64
import inspect
import io
import json
import math
import pickle
import re
import struct
import zipfile
import zlib
from dataclasses import dataclass
from pathlib import Path
from typing import IO, Any

import numpy as np
from gymnasium import spaces


class UntrustedPolicyError(ValueError):
    """The zip needs unpickling to load; only ``trust=True`` may do that."""


class PolicyFileError(ValueError):
    """A policy file holds a malformed value or one beyond a bound of this module; the
    message names the file, the field and the bound."""


#: The most members of a policy zip (SB3 writes 6) and of the torch zip ``policy.pth``
#: (one per tensor and a few more); each may take at most 1 KiB of the zip's directory.
MAX_MEMBERS = 64
MAX_WEIGHT_RECORDS = 4096
#: The most bytes the ``data`` JSON may declare (the shipped policies: under 0.6 MB).
MAX_DATA_BYTES = 64 * 2**20
#: The most bytes ``policy.pth`` may declare, and its records together.
MAX_WEIGHTS_BYTES = 512 * 2**20
#: The longest text of one ``policy_kwargs`` entry, and of one space's stored text (numpy
#: spells out at most 1,000 values of an array).
MAX_KWARGS_CHARS = 4096
MAX_SPACE_CHARS = 2**20
#: The most dimensions of an observation or action array, and the most bytes of one
#: observation (all its arrays) or action: 64 MiB, room for two of the largest panoramas
#: the envs make (1024 x 4096 x 3 bytes, 12 MiB).
MAX_DIMS = 4
MAX_SPACE_BYTES = 64 * 2**20
#: The most actions of a ``Discrete`` action space.
MAX_ACTIONS = 2**16
#: The most weights of the network (400 MB as float32), and the most values its layers
#: output for one observation.
MAX_PARAMETERS = 100_000_000
MAX_ACTIVATIONS = 100_000_000

_DTYPES = ("bool", "int8", "uint8", "int16", "uint16", "int32", "uint32", "int64", "float16",
           "float32", "float64")
_END_RECORD = struct.Struct("<4s4H2LH")   # a zip's end of central directory record
#: Modules of this package under the names that older releases pickled, for
#: ``trust=True`` (``train`` became ``homing_train``).
RENAMED_MODULES = {"train.extractor": "homing_train.learning.extractor"}


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


@dataclass(frozen=True)
class StoredPolicy:
    """What a policy zip's ``data`` describes, read and checked: the network to build."""

    policy_class: type
    observation_space: spaces.Space
    action_space: spaces.Space
    policy_kwargs: dict[str, Any]


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


def _short(value: Any, limit: int = 80) -> str:
    """``repr(value)`` for a message, classes by name, cut to ``limit`` characters."""
    if isinstance(value, dict):
        value = {k: v.__name__ if isinstance(v, type) else v for k, v in value.items()}
    text = repr(value)
    return text if len(text) <= limit else text[:limit - 3] + "..."


def _class_by_name(text: str, allowed: dict[str, type], what: str, path: str) -> type:
    match = _CLASS.match(text.strip())
    name = match.group(1).rsplit(".", 1)[-1] if match else None
    if name not in allowed:
        raise UntrustedPolicyError(
            f"{path}: {what} {text!r} is not one of the known classes {sorted(allowed)}; "
            f"loading it would unpickle code from the file (pass --trust-policy to allow)")
    return allowed[name]


def _directory_bytes(file: IO[bytes]) -> int:
    """The size of a zip's central directory as its end record declares it, read before
    :mod:`zipfile` parses the directory."""
    size = file.seek(0, io.SEEK_END)
    file.seek(max(0, size - _END_RECORD.size - 0xFFFF))   # the record ends in a comment
    tail = file.read()
    at = tail.rfind(b"PK\x05\x06")
    if at < 0 or len(tail) - at < _END_RECORD.size:
        raise zipfile.BadZipFile("File is not a zip file")
    return _END_RECORD.unpack_from(tail, at)[5]


def _opened_zip(file: IO[bytes], max_members: int, what: str) -> zipfile.ZipFile:
    """``file`` opened as a zip once its directory is within ``max_members`` members (and
    1 KiB each); :class:`PolicyFileError` naming ``what`` otherwise."""
    directory = _directory_bytes(file)
    if directory > 1024 * max_members:
        raise PolicyFileError(f"{what}: a zip directory of {directory:,} bytes, more than the "
                              f"{1024 * max_members:,} allowed ({max_members} members)")
    archive = zipfile.ZipFile(file)
    if len(archive.infolist()) > max_members:
        archive.close()
        raise PolicyFileError(f"{what}: {len(archive.infolist())} zip members, more than the "
                              f"{max_members} allowed")
    return archive


def _member(archive: zipfile.ZipFile, name: str, max_bytes: int, path: str) -> bytes:
    """The member ``name`` of ``archive``, read once its declared size is within
    ``max_bytes`` (:mod:`zipfile` reads no more than it declares)."""
    try:
        info = archive.getinfo(name)
    except KeyError:
        raise PolicyFileError(f"{path}: not a stable-baselines3 model zip (no member "
                              f"{name!r})") from None
    if info.file_size > max_bytes:
        raise PolicyFileError(f"{path}: member {name!r} declares {info.file_size:,} bytes, "
                              f"more than the {max_bytes:,} allowed")
    return archive.read(info)


def _checked_weights(weights: bytes, path: str) -> bytes:
    """``policy.pth``, once the torch zip it is declares at most
    :data:`MAX_WEIGHT_RECORDS` records of :data:`MAX_WEIGHTS_BYTES` bytes together."""
    what = f"{path}: policy.pth"
    try:
        with _opened_zip(io.BytesIO(weights), MAX_WEIGHT_RECORDS, what) as records:
            declared = sum(info.file_size for info in records.infolist())
    except zipfile.BadZipFile as err:
        raise PolicyFileError(f"{what}: not torch's zip format ({err})") from None
    if declared > MAX_WEIGHTS_BYTES:
        raise PolicyFileError(f"{what}: its records declare {declared:,} bytes, more than the "
                              f"{MAX_WEIGHTS_BYTES:,} allowed")
    return weights


def _read_zip(path: str) -> tuple[dict, bytes]:
    """The ``data`` JSON and the ``policy.pth`` bytes of the zip at ``path``, each size
    checked before it is read."""
    try:
        with open(path, "rb") as file, _opened_zip(file, MAX_MEMBERS, path) as archive:
            text = _member(archive, "data", MAX_DATA_BYTES, path)
            weights = _checked_weights(_member(archive, "policy.pth", MAX_WEIGHTS_BYTES,
                                               path), path)
        data = json.loads(text)
    except FileNotFoundError:
        raise ValueError(f"policy file {path!r} does not exist") from None
    except RecursionError:
        raise PolicyFileError(f"{path}: its data JSON is nested deeper than Python parses "
                              f"(about 1,000 levels)") from None
    except (zipfile.BadZipFile, zlib.error, EOFError, NotImplementedError, RuntimeError,
            json.JSONDecodeError, UnicodeDecodeError, OSError) as err:
        raise PolicyFileError(f"{path}: not a stable-baselines3 model zip ({err})") from None
    if not isinstance(data, dict):
        raise PolicyFileError(f"{path}: its data JSON is not an object but "
                              f"{type(data).__name__}")
    return data, weights


def _checked_text(value: Any, limit: int, field: str, path: str) -> str:
    if not isinstance(value, str) or len(value) > limit:
        raise PolicyFileError(f"{path}: {field} must be a text of at most {limit:,} "
                              f"characters, got {_short(value)}")
    return value


def _checked_int(value: Any, low: int, high: int, field: str, path: str) -> int:
    """``value`` (an integer or its text) in ``[low, high]``."""
    try:
        number = int(value) if isinstance(value, (int, str)) and len(str(value)) < 20 else None
    except ValueError:
        number = None
    if number is None or isinstance(value, bool) or not low <= number <= high:
        raise PolicyFileError(f"{path}: {field} must be an integer in [{low:,}, {high:,}], "
                              f"got {_short(value)}")
    return number


def _box_layout(shape: Any, dtype: Any, field: str, path: str) -> tuple[tuple[int, ...],
                                                                      np.dtype]:
    """The shape and dtype of a ``Box``, checked: 1 to :data:`MAX_DIMS` positive sides,
    one of the numeric dtypes."""
    if dtype not in _DTYPES:
        raise PolicyFileError(f"{path}: {field} dtype {_short(dtype)} is not one of {_DTYPES}")
    if not (isinstance(shape, (tuple, list)) and 1 <= len(shape) <= MAX_DIMS
            and all(isinstance(v, int) and not isinstance(v, bool) and v >= 1 for v in shape)):
        raise PolicyFileError(f"{path}: {field} shape {_short(shape)} must be 1 to {MAX_DIMS} "
                              f"positive integers")
    return tuple(shape), np.dtype(dtype)


def _check_bytes(layouts: list[tuple[tuple[int, ...], np.dtype]], field: str, path: str) -> None:
    total = sum(math.prod(shape) * dtype.itemsize for shape, dtype in layouts)
    if total > MAX_SPACE_BYTES:
        raise PolicyFileError(f"{path}: {field} {[shape for shape, _ in layouts]} takes "
                              f"{total:,} bytes a step, more than the {MAX_SPACE_BYTES:,} "
                              f"allowed")


def _shape_text(text: str, field: str, path: str) -> tuple[int, ...]:
    """``"3, 32, 128"`` -> ``(3, 32, 128)``."""
    try:
        return tuple(int(v) for v in text.replace(" ", "").split(",") if v)
    except ValueError:
        raise PolicyFileError(f"{path}: {field} shape {_short(text)} is not a list of "
                              f"integers") from None


def _bound(text: str, shape: tuple[int, ...], field: str, path: str) -> float | np.ndarray:
    """A ``Box`` bound from its stored text: one number, or one per element of ``shape``."""
    if "..." in text:
        raise UntrustedPolicyError(f"{path}: {field} {_short(text)} lists only some of its "
                                   f"values (pass --trust-policy to unpickle them)")
    try:
        values = np.array(text.replace("[", " ").replace("]", " ").split(), dtype=np.float64)
    except ValueError:
        raise PolicyFileError(f"{path}: {field} {_short(text)} is not numbers") from None
    if values.size == 1:
        return float(values[0])
    if values.size != math.prod(shape):
        raise PolicyFileError(f"{path}: {field} has {values.size} values; its shape {shape} "
                              f"takes 1 or {math.prod(shape)}")
    return values.reshape(shape)


def _box(low: str, high: str, layout: tuple[tuple[int, ...], np.dtype], field: str,
         path: str) -> spaces.Box:
    shape, dtype = layout
    try:
        return spaces.Box(_bound(low, shape, f"{field} low", path),
                          _bound(high, shape, f"{field} high", path), shape, dtype)
    except (TypeError, AssertionError) as err:
        raise PolicyFileError(f"{path}: {field} is not a valid Box ({err})") from None


def _space(entry: Any, field: str, path: str) -> spaces.Space:
    """The space stored as ``entry`` (the ``data`` field ``field``), every size checked
    before the space is made."""
    if not isinstance(entry, dict):
        raise PolicyFileError(f"{path}: {field} must be a JSON object, got {_short(entry)}")
    kind = str(entry.get(":type:", ""))
    if "spaces.dict.Dict" in kind:
        text = _checked_text(entry.get("spaces", ""), MAX_SPACE_CHARS, f"{field} spaces", path)
        found = {m.group(1): m for m in re.finditer(r"'(\w+)': " + _BOX.pattern, text)}
        if not found or len(found) != text.count("': "):
            raise UntrustedPolicyError(f"{path}: cannot read the Dict {field} {_short(text)} "
                                       f"without unpickling (only Box members)")
        layouts = {name: _box_layout(_shape_text(m.group(4), field, path), m.group(5),
                                     f"{field} {name!r}", path) for name, m in found.items()}
        _check_bytes(list(layouts.values()), field, path)
        return spaces.Dict({name: _box(m.group(2), m.group(3), layouts[name],
                                       f"{field} {name!r}", path) for name, m in found.items()})
    if "spaces.box.Box" in kind:
        shape = entry.get("_shape")
        if isinstance(shape, str):
            shape = _shape_text(_checked_text(shape, MAX_KWARGS_CHARS, f"{field} shape",
                                              path).strip("()[]"), field, path)
        layout = _box_layout(shape, entry.get("dtype"), field, path)
        _check_bytes([layout], field, path)
        low, high = (_checked_text(str(entry.get(f"{end}_repr") or entry.get(end, "")),
                                   MAX_SPACE_CHARS, f"{field} {end}", path)
                     for end in ("low", "high"))
        return _box(low, high, layout, field, path)
    if "spaces.discrete.Discrete" in kind:
        return spaces.Discrete(_checked_int(entry.get("n"), 1, MAX_ACTIONS, f"{field} n", path),
                               start=_checked_int(entry.get("start", 0), -2**31, 2**31,
                                                  f"{field} start", path))
    raise UntrustedPolicyError(f"{path}: space of type {kind!r} cannot be read without "
                               f"unpickling (pass --trust-policy to allow)")


def _literal(value: Any, key: str, path: str) -> Any:
    """A ``policy_kwargs`` entry other than a class: stored as JSON, or as the ``repr`` of
    plain data; at most :data:`MAX_KWARGS_CHARS` characters either way."""
    text = value if isinstance(value, str) else json.dumps(value)
    if len(text) > MAX_KWARGS_CHARS:
        raise PolicyFileError(f"{path}: policy_kwargs[{key!r}] has {len(text):,} characters, "
                              f"more than the {MAX_KWARGS_CHARS:,} allowed")
    if not isinstance(value, str):
        return value
    try:
        return ast.literal_eval(text)
    except (ValueError, SyntaxError, RecursionError, MemoryError):
        raise UntrustedPolicyError(
            f"{path}: policy_kwargs[{key!r}] = {_short(text)} is not plain data (pass "
            f"--trust-policy to unpickle it)") from None


def _policy_kwargs(entry: Any, path: str) -> dict[str, Any]:
    if not entry:
        return {}
    if not isinstance(entry, dict):
        raise PolicyFileError(f"{path}: policy_kwargs must be a JSON object, got "
                              f"{_short(entry)}")
    out: dict[str, Any] = {}
    for key, value in entry.items():
        if key.startswith(":"):
            continue
        if key == "features_extractor_class":
            out[key] = _class_by_name(str(value), _extractor_classes(), "features extractor",
                                      path)
        elif key == "activation_fn":
            out[key] = _class_by_name(str(value), _activation_classes(), "activation", path)
        else:
            out[key] = _literal(value, key, path)
    return out


def _arguments(cls: type, skip: int) -> list[str] | None:
    """The keyword arguments of ``cls`` after its first ``skip``; ``None`` if it takes any
    (``**kwargs``)."""
    parameters = list(inspect.signature(cls).parameters.values())[skip:]
    if any(p.kind is p.VAR_KEYWORD for p in parameters):
        return None
    return [p.name for p in parameters]


def _check_keys(given: Any, allowed: list[str] | None, what: str, source: str) -> None:
    if not isinstance(given, dict):
        raise PolicyFileError(f"{source}: {what} must be a mapping, got {_short(given)}")
    unknown = sorted(str(key) for key in given if allowed is not None and key not in allowed)
    if unknown:
        raise PolicyFileError(f"{source}: unknown {what} {unknown}; allowed: {allowed}")


def network_size(policy_class: type, observation_space: spaces.Space,
                 action_space: spaces.Space, policy_kwargs: dict[str, Any]) -> tuple[int, int]:
    """``(parameters, activations)`` of the network ``policy_class(observation_space,
    action_space, lr_schedule, **policy_kwargs)``: its weights, and the values its
    features extractor's layers output for one observation. Built on torch's ``meta``
    device: no weight or activation is allocated (one observation sample is)."""
    import torch

    class OnMeta(policy_class):
        @property
        def device(self) -> torch.device:   # where SB3 moves parts it builds
            return torch.device("meta")

    outputs: list[int] = []
    with torch.device("meta"), torch.no_grad():
        policy = OnMeta(observation_space, action_space, lambda _: 0.0, **policy_kwargs)
        for module in policy.modules():
            if next(module.children(), None) is None:
                module.register_forward_hook(
                    lambda _m, _i, out: outputs.append(getattr(out, "numel", int)()))
        policy.extract_features(policy.obs_to_tensor(observation_space.sample())[0])
    return sum(p.numel() for p in policy.parameters()), sum(outputs)


def checked_network(policy_class: type, observation_space: spaces.Space,
                    action_space: spaces.Space, policy_kwargs: dict[str, Any],
                    source: str) -> None:
    """:class:`PolicyFileError` naming ``source`` unless ``policy_kwargs`` holds only
    arguments of ``policy_class`` and of its features extractor, and builds a network of
    at most :data:`MAX_PARAMETERS` parameters and :data:`MAX_ACTIVATIONS` values output by
    its layers for one observation (:func:`network_size`, nothing allocated)."""
    _check_keys(policy_kwargs, _arguments(policy_class, 3), "policy_kwargs", source)
    extractor = policy_kwargs.get("features_extractor_class", inspect.signature(
        policy_class).parameters["features_extractor_class"].default)
    if not isinstance(extractor, type):
        raise PolicyFileError(f"{source}: policy_kwargs features_extractor_class must be a "
                              f"class, got {_short(extractor)}")
    _check_keys(policy_kwargs.get("features_extractor_kwargs") or {},
                _arguments(extractor, 1), "policy_kwargs features_extractor_kwargs", source)
    given = f"policy_kwargs {_short(policy_kwargs, 300)}"
    try:
        parameters, activations = network_size(policy_class, observation_space, action_space,
                                               policy_kwargs)
    except Exception as err:  # the network's own checks raise many types
        raise PolicyFileError(f"{source}: {given} build no network for these spaces "
                              f"({type(err).__name__}: {' '.join(str(err).split())[:200]})"
                              ) from None
    if parameters > MAX_PARAMETERS:
        raise PolicyFileError(f"{source}: {given} make a network of {parameters:,} "
                              f"parameters, more than the {MAX_PARAMETERS:,} allowed")
    if activations > MAX_ACTIVATIONS:
        raise PolicyFileError(f"{source}: {given} make layers that output {activations:,} "
                              f"values for one observation, more than the "
                              f"{MAX_ACTIVATIONS:,} allowed")


def stored_policy(data: dict, path: str) -> StoredPolicy:
    """The network that a zip's ``data`` JSON describes, each field and size checked
    (the one place that reads the JSON)."""
    entry = data.get("policy_class")
    doc = entry.get("__doc__") if isinstance(entry, dict) else None
    policy_class = _policy_classes().get(doc) if isinstance(doc, str) else None
    if policy_class is None:
        raise UntrustedPolicyError(f"{path}: the policy class is not one of SB3's actor-critic "
                                   f"policies (pass --trust-policy to unpickle it)")
    observation_space = _space(data.get("observation_space"), "observation_space", path)
    action_space = _space(data.get("action_space"), "action_space", path)
    kwargs = _policy_kwargs(data.get("policy_kwargs"), path)
    checked_network(policy_class, observation_space, action_space, kwargs, path)
    return StoredPolicy(policy_class, observation_space, action_space, kwargs)


class _RenamingUnpickler(pickle.Unpickler):
    """An unpickler that finds :data:`RENAMED_MODULES` under their current names."""

    def find_class(self, module: str, name: str) -> Any:
        return super().find_class(RENAMED_MODULES.get(module, module), name)


def _trusted_model(path: str):
    """``PPO.load(path)``, with the zip's pickled entries unpickled by
    :class:`_RenamingUnpickler` (runs code from the file). An entry that fails to
    unpickle as SB3 tolerates is left to SB3, which warns."""
    from stable_baselines3 import PPO

    data, _ = _read_zip(path)
    objects = {}
    for key, entry in data.items():
        if isinstance(entry, dict) and isinstance(entry.get(":serialized:"), str):
            try:
                objects[key] = _RenamingUnpickler(
                    io.BytesIO(base64.b64decode(entry[":serialized:"]))).load()
            except (RuntimeError, TypeError, AttributeError):
                pass
    try:
        return PPO.load(path, device="cpu", custom_objects=objects)
    except ImportError as err:
        raise ValueError(f"{path}: --trust-policy cannot unpickle it: {err}") from None


def load_policy(path: str | Path, trust: bool = False) -> LoadedPolicy:
    """The policy network saved in the SB3 PPO zip at ``path``, on the CPU, read without
    unpickling (see the module docstring); ``trust=True`` uses ``PPO.load`` instead."""
    import torch

    path = str(path)
    if trust:
        model = _trusted_model(path)
        return LoadedPolicy(model.policy, model.observation_space, model.action_space)
    data, weights = _read_zip(path)
    stored = stored_policy(data, path)
    policy = stored.policy_class(stored.observation_space, stored.action_space,
                                 lambda _: 0.0, **stored.policy_kwargs)
    try:
        state = torch.load(io.BytesIO(weights), map_location="cpu", weights_only=True)
        policy.load_state_dict(state)
    except Exception as err:  # torch raises many types for a bad or mismatched file
        raise ValueError(f"{path}: policy weights do not load ({type(err).__name__}: "
                         f"{err})") from None
    policy.set_training_mode(False)
    return LoadedPolicy(policy, stored.observation_space, stored.action_space)
