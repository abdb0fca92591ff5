"""A stable-baselines3 features extractor made for panoramas and goal images.

:class:`PanoramaGoalExtractor` stacks the current panorama and the goal panorama as
channels (early fusion: the first convolution already compares the two images, which
image-goal navigation work reports to work far better than separate encoders), and runs
convolutions with *circular* padding along azimuth, since a 360-degree panorama has no left
or right edge, and zero padding along elevation. Other Box observations (e.g.
``odometry``, ``signature``) are flattened and concatenated after the convolutional trunk.
Sized for CPU training: a 4 x 4 stride-4 patch layer, two stride-2 convolutions and
one linear layer (about 8 M multiply-adds per 48 x 256 sample).

:class:`HorizonBandExtractor` (``"band"``) is smaller still, for throughput on CPU cores:
it treats the rows of a low panorama (a band around the horizon, e.g. 16 x 128) as
channels and runs 1-D circular convolutions over azimuth only (about 1.5 M multiply-adds
per 16 x 128 sample with the default layers).
"""

from __future__ import annotations

import gymnasium as gym
import torch
from stable_baselines3.common.preprocessing import is_image_space
from stable_baselines3.common.torch_layers import BaseFeaturesExtractor
from torch import nn
from torch.nn import functional as F

from homing_train.learning import EXTRACTORS



class CircularConv(nn.Module):
    """``Conv2d`` with circular padding along the width (azimuth) and zeros along the
    height, then ReLU. The padding, ``(kernel - stride + 1) // 2`` on each side, keeps the
    output at ``input / stride`` (a patch layer, ``kernel == stride``, needs none)."""

    def __init__(self, c_in: int, c_out: int, kernel: int, stride: int):
        super().__init__()
        self.pad = max(kernel - stride + 1, 0) // 2
        self.conv = nn.Conv2d(c_in, c_out, kernel, stride, padding=(self.pad, 0))

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        x = F.pad(x, (self.pad, self.pad, 0, 0), mode="circular")
        return F.relu(self.conv(x))


class CircularConv1d(nn.Module):
    """``Conv1d`` over azimuth with circular padding ``(kernel - stride + 1) // 2`` on each
    side (the output keeps ``width / stride``), then ReLU."""

    def __init__(self, c_in: int, c_out: int, kernel: int, stride: int):
        super().__init__()
        self.pad = max(kernel - stride + 1, 0) // 2
        self.conv = nn.Conv1d(c_in, c_out, kernel, stride)

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        return F.relu(self.conv(F.pad(x, (self.pad, self.pad), mode="circular")))


class PanoramaGoalExtractor(BaseFeaturesExtractor):
    """Early-fusion CNN over ``image_keys`` (default: panorama and goal) stacked as channels;
    other keys are flattened and appended. ``layers``: (channels, kernel, stride) of each
    convolution. Output: ``features_dim`` + extra values."""

    conv = CircularConv

    def __init__(self, observation_space: gym.spaces.Dict, features_dim: int = 256,
                 image_keys: tuple[str, ...] = ("panorama", "goal"),
                 layers: tuple[tuple[int, int, int], ...] = ((32, 4, 4), (64, 3, 2),
                                                             (64, 3, 2))):
        missing = [k for k in image_keys if k not in observation_space.spaces]
        if missing:
            raise ValueError(f"{type(self).__name__} needs observation keys {missing}; the "
                             f"space has {list(observation_space.spaces)}")
        for key in image_keys:
            if not is_image_space(observation_space[key], check_channels=False):
                raise ValueError(f"observation {key!r} is not an image space: "
                                 f"{observation_space[key]}")
        extra_keys = [k for k in observation_space.spaces if k not in image_keys]
        extra_dim = sum(int(torch.tensor(observation_space[k].shape).prod()) for k in extra_keys)
        super().__init__(observation_space, features_dim + extra_dim)
        self.image_keys = tuple(image_keys)
        self.extra_keys = tuple(extra_keys)
        sample = self.fused({k: torch.zeros(1, *observation_space[k].shape) for k in image_keys})
        self.cnn = self.trunk(sample.shape[1], layers)
        with torch.no_grad():
            n_flat = self.cnn(sample).shape[1]
        self.linear = nn.Sequential(nn.Linear(n_flat, features_dim), nn.ReLU())

    def fused(self, observations: dict[str, torch.Tensor]) -> torch.Tensor:
        """The images stacked as channels: ``(N, sum C, H, W)`` (SB3 gives CHW)."""
        return torch.cat([observations[k] for k in self.image_keys], dim=1)

    def trunk(self, c_in: int, layers: tuple[tuple[int, int, int], ...]) -> nn.Sequential:
        """The convolutions (:attr:`conv`, circular along azimuth), then a flatten."""
        convs = []
        for c_out, kernel, stride in layers:
            convs.append(self.conv(c_in, c_out, kernel, stride))
            c_in = c_out
        return nn.Sequential(*convs, nn.Flatten())

    def forward(self, observations: dict[str, torch.Tensor]) -> torch.Tensor:
        features = [self.linear(self.cnn(self.fused(observations)))]
        features += [observations[k].flatten(1) for k in self.extra_keys]
        return torch.cat(features, dim=1)


class HorizonBandExtractor(PanoramaGoalExtractor):
    """:class:`PanoramaGoalExtractor` with every row of every image as a channel of a 1-D
    signal over azimuth: ``(C, H, W)`` images give ``sum(C * H)`` channels of width
    ``W``, and ``layers`` are (channels, kernel, stride) of 1-D circular convolutions.
    Meant for low panoramas (a band around the horizon): only the first layer's cost
    grows with ``H``."""

    conv = CircularConv1d

    def __init__(self, observation_space: gym.spaces.Dict, features_dim: int = 128,
                 image_keys: tuple[str, ...] = ("panorama", "goal"),
                 layers: tuple[tuple[int, int, int], ...] = ((32, 5, 2), (64, 5, 2),
                                                             (64, 3, 2))):
        super().__init__(observation_space, features_dim, image_keys, layers)

    def fused(self, observations: dict[str, torch.Tensor]) -> torch.Tensor:
        """The images' rows stacked as channels: ``(N, sum C * H, W)``."""
        return torch.cat([observations[k].flatten(1, 2) for k in self.image_keys], dim=1)


def policy_kwargs_for(extractor: str, **extractor_kwargs) -> dict:
    """``policy_kwargs`` for ``PPO("MultiInputPolicy", ...)``: ``"panorama"`` uses
    :class:`PanoramaGoalExtractor`, ``"band"`` :class:`HorizonBandExtractor`,
    ``"combined"`` SB3's default ``CombinedExtractor``."""
    if extractor not in EXTRACTORS:
        raise ValueError(f"unknown extractor {extractor!r}; allowed: {EXTRACTORS}")
    if extractor == "combined":
        return {}
    cls = HorizonBandExtractor if extractor == "band" else PanoramaGoalExtractor
    return {"features_extractor_class": cls, "features_extractor_kwargs": extractor_kwargs}
