"""Many envs in one process: :class:`~homing_gym.vector.native.NativeVectorEnv` (the
vector entry point of every registered id) around
:class:`~homing_gym.vector.batch.EnvBatch`."""

from homing_gym.vector.batch import MAX_NUM_ENVS, EnvBatch, EnvFailedError
from homing_gym.vector.native import NativeVectorEnv

__all__ = ["MAX_NUM_ENVS", "EnvBatch", "EnvFailedError", "NativeVectorEnv"]
