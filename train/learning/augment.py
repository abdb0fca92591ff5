"""Appearance augmentation of the training envs' images (``homing-train --hp augment=...``).

Each training episode gets its own colour transform, applied alike to every image of its
observations (the current panorama and the goal snapshot, which a real world lights
alike): a hue rotation about the grey axis, a saturation scale (0: grey), per-channel
gains, a brightness scale and a gamma. So a policy that trained on green meadows under a
blue sky also sees brown, grey and dusk-tinted ones, and must home on what does not
change with the palette (the layout, luminance edges). The evaluation envs and every
protocol see the images as rendered: augmentation is a training device only.

Per pixel ``x`` (RGB in [0, 1]): ``y = gamma_curve(brightness * gains * (M x))``, ``M``
the hue rotation by ``theta`` (radians, about the axis ``(1, 1, 1)``) times the
saturation blend ``s I + (1 - s) L`` (``L`` the matrix mapping a colour to its Rec. 601
luma in every channel), the result clipped to [0, 1] (a bright scene saturates as a
camera's would) and rounded to uint8.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np
from stable_baselines3.common.vec_env import VecEnvWrapper

from homing_gym.validation import require_number

#: Rec. 601 luma weights.
LUMA = np.array([0.299, 0.587, 0.114])


def _interval(name: str, value, low: float, high: float) -> tuple[float, float]:
    if not (isinstance(value, (list, tuple)) and len(value) == 2):
        raise ValueError(f"augment {name}: a [min, max] pair, got {value!r}")
    a, b = (require_number(f"augment {name}", v, low, high, "") for v in value)
    if a > b:
        raise ValueError(f"augment {name}: min {a} above max {b}")
    return float(a), float(b)


@dataclass(frozen=True)
class AugmentSettings:
    """Ranges each episode's transform is drawn from (uniformly; ``gamma`` log-uniformly).

    ``hue``: the largest hue rotation (radians, either way; pi: any hue); ``saturation``,
    ``gain`` (each channel's own), ``brightness``, ``gamma``: ``[min, max]`` factors.
    Every range includes the identity by default, and ``hue=0``, ``[1, 1]`` everywhere is
    the identity."""

    hue: float = math.pi
    saturation: tuple[float, float] = (0.2, 1.3)
    gain: tuple[float, float] = (0.85, 1.15)
    brightness: tuple[float, float] = (0.6, 1.3)
    gamma: tuple[float, float] = (0.7, 1.4)

    def __post_init__(self) -> None:
        object.__setattr__(self, "hue", float(require_number("augment hue", self.hue, 0.0,
                                                             math.pi, "radians")))
        for name, low, high in (("saturation", 0.0, 3.0), ("gain", 0.1, 3.0),
                                ("brightness", 0.1, 3.0), ("gamma", 0.2, 5.0)):
            object.__setattr__(self, name, _interval(name, getattr(self, name), low, high))

    @classmethod
    def from_value(cls, value) -> "AugmentSettings":
        """From the ``augment`` setting: a mapping of the fields above (``{}``: the
        defaults); ``ValueError`` naming an unknown key and the allowed ones."""
        if not isinstance(value, dict):
            raise ValueError(f"augment: a mapping of {sorted(asdict(cls()))} (or {{}} for the "
                             f"defaults, null for none), got {value!r}")
        unknown = sorted(set(value) - set(asdict(cls())))
        if unknown:
            raise ValueError(f"augment: unknown keys {unknown}; allowed: {sorted(asdict(cls()))}")
        return cls(**value)

    def draw(self, rng: np.random.Generator) -> tuple[np.ndarray, float]:
        """``(A, gamma)``: one episode's colour matrix ``A`` (3 x 3, applied to RGB column
        vectors, gains and brightness included) and its gamma."""
        theta = rng.uniform(-self.hue, self.hue)
        c, s, k = math.cos(theta), math.sin(theta), 1.0 / 3.0
        r = math.sqrt(k)
        # Rodrigues' rotation by theta about the unit grey axis (1, 1, 1) / sqrt(3)
        cross = np.array([[0.0, -r, r], [r, 0.0, -r], [-r, r, 0.0]])
        rotation = c * np.eye(3) + s * cross + (1 - c) * np.full((3, 3), k)
        sat = rng.uniform(*self.saturation)
        blend = sat * np.eye(3) + (1 - sat) * np.tile(LUMA, (3, 1))
        gains = rng.uniform(*self.gain, size=3) * rng.uniform(*self.brightness)
        gamma = math.exp(rng.uniform(math.log(self.gamma[0]), math.log(self.gamma[1])))
        return gains[:, None] * (rotation @ blend), gamma


def transformed(images: np.ndarray, matrix: np.ndarray, gamma: float) -> np.ndarray:
    """``images (..., 3)`` uint8 RGB through one colour transform (:meth:`AugmentSettings.
    draw`): uint8 of the same shape."""
    return batch_transformed(images[None], matrix[None], np.array([gamma]))[0]


def batch_transformed(images: np.ndarray, matrices: np.ndarray,
                      gammas: np.ndarray) -> np.ndarray:
    """``images (N, ..., 3)`` uint8 RGB, image ``i`` through ``matrices[i]`` and
    ``gammas[i]`` (:meth:`AugmentSettings.draw`), in one call: uint8 of the same shape."""
    x = images.reshape(len(images), -1, 3).astype(np.float32) * np.float32(1 / 255)
    y = np.clip(x @ matrices.transpose(0, 2, 1).astype(np.float32), 0.0, 1.0)
    y **= gammas.astype(np.float32)[:, None, None]
    return np.rint(y * 255).astype(np.uint8).reshape(images.shape)


class AugmentedImages(VecEnvWrapper):
    """A vector env (dict observations of HWC uint8 images, before SB3's channel-first
    transpose) whose image keys ``image_keys`` (default: ``panorama``, ``goal`` and, where
    observed, ``previous``) go through each env's colour transform, drawn anew (from
    ``seed``'s stream) whenever that env's episode starts."""

    def __init__(self, venv, settings: AugmentSettings, seed: int,
                 image_keys: tuple[str, ...] | None = None):
        super().__init__(venv)
        if image_keys is None:
            image_keys = ("panorama", "goal", *(("previous",) if "previous" in
                                                venv.observation_space.spaces else ()))
        missing = [k for k in image_keys if k not in venv.observation_space.spaces]
        if missing:
            raise ValueError(f"augment needs the image keys {missing}; the observations have "
                             f"{list(venv.observation_space.spaces)}")
        self.settings, self.image_keys = settings, image_keys
        self._rng = np.random.default_rng(seed)
        self._draws = [settings.draw(self._rng) for _ in range(self.num_envs)]

    def _apply(self, obs: dict) -> dict:
        matrices = np.stack([m for m, _ in self._draws])
        gammas = np.array([g for _, g in self._draws])
        for key in self.image_keys:
            obs[key] = batch_transformed(obs[key], matrices, gammas)
        return obs

    def reset(self):
        self._draws = [self.settings.draw(self._rng) for _ in range(self.num_envs)]
        return self._apply(self.venv.reset())

    def step_wait(self):
        obs, rewards, dones, infos = self.venv.step_wait()
        for i in np.flatnonzero(dones):
            ended = infos[i].get("terminal_observation")
            if ended is not None:          # the last view of the episode that ended
                infos[i]["terminal_observation"] = {
                    k: (transformed(v, *self._draws[i]) if k in self.image_keys else v)
                    for k, v in ended.items()}
            self._draws[i] = self.settings.draw(self._rng)
        return self._apply(obs), rewards, dones, infos
