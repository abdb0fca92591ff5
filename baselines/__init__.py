"""Scripted visual-homing controllers behind one interface, and their registry.

>>> import baselines
>>> homing_baselines.available()
['bearing', 'bearing-basic', 'bearing-complementary', 'bearing-longrange', 'distance',
 'multires', 'oracle', 'random', 'selfsimilar', 'snapshot', 'warping']
>>> controller = homing_baselines.make("oracle", step_length=0.2)
"""

from __future__ import annotations

import dataclasses
from typing import Any

from homing_baselines.base import Controller
from homing_baselines.motion import MotionHelper, MotionSpec, Move
from homing_baselines.bearing import (BasicBearingController, BearingController,
                               ComplementaryBearingController)
from homing_baselines.bearing_longrange import LongRangeBearingController
from homing_baselines.alv import ALVController
from homing_baselines.did import DIDController
from homing_baselines.distance import DistanceController
from homing_baselines.infomax import InfomaxController
from homing_baselines.min_warping import MinWarpingController
from homing_baselines.multires import MultiResController
from homing_baselines.oracle import OracleController
from homing_baselines.perfect_memory import PerfectMemoryController
from homing_baselines.random_walk import RandomController
from homing_baselines.selfsimilar import SelfSimilarController
from homing_baselines.snapshot import SnapshotController
from homing_baselines.warping import WarpingController

_REGISTRY: dict[str, type[Controller]] = {}


def register(name: str, cls: type[Controller]) -> None:
    """Make controller class ``cls`` available as ``homing_baselines.make(name)``."""
    if not (isinstance(cls, type) and issubclass(cls, Controller)):
        raise TypeError(f"{cls!r} is not a Controller subclass")
    cls.name = name
    _REGISTRY[name] = cls


def available() -> list[str]:
    """Names of the registered controllers."""
    return sorted(_REGISTRY)


def controller_class(name: str) -> type[Controller]:
    """The class registered under ``name``; ``ValueError`` listing the names if unknown."""
    if name not in _REGISTRY:
        raise ValueError(f"unknown controller {name!r}; available: {available()}")
    return _REGISTRY[name]


def parameters(name: str) -> dict[str, Any]:
    """Parameter names of a controller with their default values."""
    return {f.name: f.default for f in dataclasses.fields(controller_class(name))}


def make(name: str, **params: Any) -> Controller:
    """A new controller ``name`` with parameter overrides; ``ValueError`` on unknown names
    or parameters."""
    cls = controller_class(name)
    unknown = sorted(set(params) - set(parameters(name)))
    if unknown:
        raise ValueError(f"controller {name!r} has no parameter(s) {unknown}; "
                         f"parameters: {parameters(name)}")
    return cls(**params)


register("oracle", OracleController)
register("random", RandomController)
register("distance", DistanceController)
register("warping", WarpingController)
register("snapshot", SnapshotController)
register("bearing", BearingController)
register("bearing-basic", BasicBearingController)
register("bearing-complementary", ComplementaryBearingController)
register("bearing-longrange", LongRangeBearingController)
register("selfsimilar", SelfSimilarController)
register("multires", MultiResController)
register("alv", ALVController)
register("did", DIDController)
register("min-warping", MinWarpingController)
register("perfect-memory", PerfectMemoryController)
register("infomax", InfomaxController)

__all__ = ["Controller", "MotionHelper", "MotionSpec", "Move", "OracleController",
           "RandomController", "available", "controller_class", "make", "parameters",
           "register"]
