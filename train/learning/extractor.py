"""A stable-baselines3 features extractor made for panoramas and goal images.

:class:`PanoramaGoalExtractor` stacks the current panorama and the goal panorama as
channels (early fusion: the first convolution already compares the two images, which
image-goal navigation work reports to work far better than separate encoders), and runs
convolutions with *circular* padding along azimuth, since a 360-degree panorama has no left
or right edge, and zero padding along elevation. Other Box observations (e.g.
``odometry``, ``signature``) are flattened and concatenated after the convolutional trunk.
Sized for CPU training: a 4 x 4 stride-4 patch layer, two stride-2 convolutions and
one linear layer (about 8 M multiply-adds per 48 x 256 sample).
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


class PanoramaGoalExtractor(BaseFeaturesExtractor):
    """Early-fusion CNN over ``image_keys`` (default: panorama and goal) stacked as channels;
    other keys are flattened and appended. ``layers``: (channels, kernel, stride) of each
    convolution. Output: ``features_dim`` + extra values."""

    def __init__(self, observation_space: gym.spaces.Dict, features_dim: int = 256,
                 image_keys: tuple[str, ...] = ("panorama", "goal"),
                 layers: tuple[tuple[int, int, int], ...] = ((32, 4, 4), (64, 3, 2),
                                                             (64, 3, 2))):
        missing = [k for k in image_keys if k not in observation_space.spaces]
        if missing:
            raise ValueError(f"PanoramaGoalExtractor needs observation keys {missing}; the "
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
        c_in = sum(observation_space[k].shape[0] for k in image_keys)   # SB3 gives CHW
        convs = []
        for c_out, kernel, stride in layers:
            convs.append(CircularConv(c_in, c_out, kernel, stride))
            c_in = c_out
        self.cnn = nn.Sequential(*convs, nn.Flatten())
        with torch.no_grad():
            sample = torch.zeros(1, sum(observation_space[k].shape[0] for k in image_keys),
                                 *observation_space[image_keys[0]].shape[1:])
            n_flat = self.cnn(sample).shape[1]
        self.linear = nn.Sequential(nn.Linear(n_flat, features_dim), nn.ReLU())

    def forward(self, observations: dict[str, torch.Tensor]) -> torch.Tensor:
        images = torch.cat([observations[k] for k in self.image_keys], dim=1)
        features = [self.linear(self.cnn(images))]
        features += [observations[k].flatten(1) for k in self.extra_keys]
        return torch.cat(features, dim=1)


def policy_kwargs_for(extractor: str, **extractor_kwargs) -> dict:
    """``policy_kwargs`` for ``PPO("MultiInputPolicy", ...)``: ``"panorama"`` uses
    :class:`PanoramaGoalExtractor`, ``"combined"`` SB3's default ``CombinedExtractor``."""
    if extractor not in EXTRACTORS:
        raise ValueError(f"unknown extractor {extractor!r}; allowed: {EXTRACTORS}")
    if extractor == "combined":
        return {}
    return {"features_extractor_class": PanoramaGoalExtractor,
            "features_extractor_kwargs": extractor_kwargs}
