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

:class:`AlignedBandExtractor` (``"align"``) aligns the goal to the current view before
comparing them: one shared encoder maps each panorama to per-column features, their
circular cross-correlation over every relative rotation gives a soft visual compass, the
goal's features are rotated by it into the robot's frame, and a head compares the two
column by column. Its output is layer-normalised, so that PPO's tanh layers behind it do
not saturate (see docs/training.md, "Saturated features").
"""

from __future__ import annotations

import math

import gymnasium as gym
import torch
from stable_baselines3.common.preprocessing import is_image_space
from stable_baselines3.common.torch_layers import BaseFeaturesExtractor
from torch import nn
from torch.nn import functional as F

from homing_train.learning import EXTRACTORS

#: The observation key :class:`AlignedBandExtractor` reads as the step before's panorama.
PREVIOUS_KEY = "previous"


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


def conv_layers(conv: type[nn.Module], c_in: int,
                layers: tuple[tuple[int, int, int], ...]) -> list[nn.Module]:
    """``conv(c_in, c_out, kernel, stride)`` for each (channels, kernel, stride) of
    ``layers``, each taking the previous one's channels."""
    modules = []
    for c_out, kernel, stride in layers:
        modules.append(conv(c_in, c_out, kernel, stride))
        c_in = c_out
    return modules


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
        extra_dim = sum(math.prod(observation_space[k].shape) for k in extra_keys)
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
        return nn.Sequential(*conv_layers(self.conv, c_in, layers), nn.Flatten())

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


class AlignedBandExtractor(BaseFeaturesExtractor):
    """Compare the goal with the current panorama after rotating it into the robot's frame.

    Both images, ``(C, H, W)`` with azimuth along ``W``, are standardised (zero mean, unit
    variance over each image: lighting offsets drop out) and go through one shared
    encoder of 1-D circular convolutions over azimuth with the ``C * H`` rows as channels,
    at full width: per-column features ``f`` and ``g``, each column scaled to unit
    length. Their circular cross-correlation ``r(s) = mean_theta <f(theta), g(theta - s)>``
    over all ``W`` shifts (by FFT) is the rotational similarity that a visual compass
    searches; ``p = softmax(temperature * r)`` (temperature learned) weights the shifts,
    and ``g_al = sum_s p(s) g(. - s)`` is the goal's features rotated into the current
    frame. The head runs circular convolutions over ``[f, g_al, f - g_al]`` (the
    difference holds the parallax, whose pattern over azimuth points home), flattens
    them with ``p`` (the heading offset), and a linear layer and LayerNorm give
    ``features_dim`` values. Other keys are flattened and appended, as in
    :class:`PanoramaGoalExtractor`. ``encoder`` and ``head``: (channels, kernel, stride)
    of each convolution; the encoder's strides must be 1 (one column per shift).

    Where the observations hold ``previous`` (the panorama of the step before, as
    ``obs_keys`` can add), it goes through the same encoder and the head also gets
    ``f - f_prev``: what changed since the last step, which a reactive policy otherwise
    cannot know (a robot pushing against a rock sees no change at all)."""

    def __init__(self, observation_space: gym.spaces.Dict, features_dim: int = 128,
                 image_keys: tuple[str, str] = ("panorama", "goal"),
                 encoder: tuple[tuple[int, int, int], ...] = ((32, 5, 1), (32, 5, 1)),
                 head: tuple[tuple[int, int, int], ...] = ((64, 5, 2), (64, 3, 2)),
                 temperature: float = 20.0):
        if len(image_keys) != 2:
            raise ValueError(f"{type(self).__name__} compares two images (current, goal); "
                             f"got image_keys {image_keys}")
        shapes = {observation_space[k].shape for k in image_keys
                  if k in observation_space.spaces}
        if len(shapes) != 1 or not all(k in observation_space.spaces for k in image_keys):
            raise ValueError(f"{type(self).__name__} needs observation keys {image_keys} "
                             f"of one shape; the space has {observation_space}")
        if any(stride != 1 for _, _, stride in encoder):
            raise ValueError(f"the encoder's strides must be 1 (one column per shift); got "
                             f"{encoder}")
        previous = PREVIOUS_KEY if PREVIOUS_KEY in observation_space.spaces else None
        if previous is not None and observation_space[previous].shape not in shapes:
            raise ValueError(f"{type(self).__name__}: observation {previous!r} must have the "
                             f"images' shape {shapes}; got {observation_space[previous].shape}")
        extra_keys = [k for k in observation_space.spaces
                      if k not in image_keys and k != previous]
        extra_dim = sum(math.prod(observation_space[k].shape) for k in extra_keys)
        super().__init__(observation_space, features_dim + extra_dim)
        channels, rows, width = observation_space[image_keys[0]].shape
        self.image_keys = tuple(image_keys)
        self.previous_key = previous
        self.extra_keys = tuple(extra_keys)
        self.encoder = nn.Sequential(*conv_layers(CircularConv1d, channels * rows, encoder))
        head_in = (3 if previous is None else 4) * encoder[-1][0]
        self.head = nn.Sequential(nn.Sequential(*conv_layers(CircularConv1d, head_in, head)),
                                  nn.Flatten())
        with torch.no_grad():
            n_flat = self.head(torch.zeros(1, head_in, width)).shape[1]
        self.log_temperature = nn.Parameter(torch.tensor(float(temperature)).log())
        # random weights that hash an image to one number (not learned, not saved)
        self.register_buffer("hash_weights", torch.rand(
            channels * rows * width, generator=torch.Generator().manual_seed(0)),
            persistent=False)
        self.linear = nn.Sequential(nn.Linear(n_flat + width, features_dim),
                                    nn.LayerNorm(features_dim))

    def column_features(self, image: torch.Tensor) -> torch.Tensor:
        """Unit-length per-column features ``(N, K, W)`` of standardised ``(N, C, H, W)``
        images (standard deviation with Bessel's correction). Written with plain sums:
        torch's ``std`` and ``F.normalize`` took 10x longer on these small tensors on a CPU,
        a third of a rollout's inference."""
        flat = image.flatten(1, 2)
        values = flat[0].numel()
        mean = flat.mean(dim=(1, 2), keepdim=True)
        centred = flat - mean
        std = (centred.square().sum(dim=(1, 2), keepdim=True) / (values - 1)).sqrt()
        features = self.encoder(centred / (std + 1e-3))
        norm = features.square().sum(dim=1, keepdim=True).sqrt().clamp_min(1e-12)
        return features / norm

    def distinct_images(self, images: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor | None]:
        """``(distinct, inverse)`` with ``images == distinct[inverse]``: each image once.
        A PPO minibatch holds many samples of one episode, all with the same goal, so the
        goals are encoded once each. Found by hashing each image to one number and then
        checked exactly; ``inverse`` is ``None`` (use ``images`` as they are) when two
        different images share a hash or nothing repeats. The hash is a product summed
        along each image alone (not a matrix product, whose rounding may differ with the
        BLAS kernel that handles an image's row), so equal images share it wherever they
        stand in the batch."""
        flat = images.flatten(1)
        keys, inverse = torch.unique((flat * self.hash_weights).sum(1), return_inverse=True)
        if len(keys) == len(images):
            return images, None
        rows = torch.arange(len(images), device=images.device)
        first = torch.empty(len(keys), dtype=torch.long,
                            device=images.device).scatter_(0, inverse, rows)
        distinct = images[first]
        if not torch.equal(distinct[inverse], images):
            return images, None
        return distinct, inverse

    def shift_weights(self, f: torch.Tensor, g: torch.Tensor) -> torch.Tensor:
        """``p(s)``, ``(N, W)``: softmax over shifts ``s`` (columns, counter-clockwise
        as the panorama's columns run) of the correlation ``mean_theta <f(theta),
        g(theta - s)>``."""
        width = f.shape[-1]
        spectrum = torch.fft.rfft(f, dim=-1) * torch.fft.rfft(g, dim=-1).conj()
        correlation = torch.fft.irfft(spectrum.sum(dim=1), n=width, dim=-1) / width
        return torch.softmax(self.log_temperature.exp() * correlation, dim=-1)

    def forward(self, observations: dict[str, torch.Tensor]) -> torch.Tensor:
        current, goal = (observations[k] for k in self.image_keys)
        # in training, each distinct goal once (the same values, less backpropagation);
        # both images through the encoder in one batch: half the calls, the same values
        goals, inverse = (self.distinct_images(goal) if torch.is_grad_enabled()
                          else (goal, None))
        views = [current] if self.previous_key is None else [current,
                                                             observations[self.previous_key]]
        features = self.column_features(torch.cat([*views, goals]))
        n = len(current)
        f, g = features[:n], features[len(views) * n:]
        if inverse is not None:
            g = g[inverse]
        p = self.shift_weights(f, g)
        width = f.shape[-1]
        aligned = torch.fft.irfft(torch.fft.rfft(g, dim=-1)
                                  * torch.fft.rfft(p, dim=-1).unsqueeze(1), n=width, dim=-1)
        parts = [f, aligned, f - aligned]
        if self.previous_key is not None:
            parts.append(f - features[n:2 * n])
        compared = self.head(torch.cat(parts, dim=1))
        features = [self.linear(torch.cat([compared, p], dim=1))]
        features += [observations[k].flatten(1) for k in self.extra_keys]
        return torch.cat(features, dim=1)


def policy_kwargs_for(extractor: str, **extractor_kwargs) -> dict:
    """``policy_kwargs`` for ``PPO("MultiInputPolicy", ...)``: ``"panorama"`` uses
    :class:`PanoramaGoalExtractor`, ``"band"`` :class:`HorizonBandExtractor`,
    ``"align"`` :class:`AlignedBandExtractor`, ``"combined"`` SB3's default
    ``CombinedExtractor``."""
    if extractor not in EXTRACTORS:
        raise ValueError(f"unknown extractor {extractor!r}; allowed: {EXTRACTORS}")
    if extractor == "combined":
        return {}
    cls = {"panorama": PanoramaGoalExtractor, "band": HorizonBandExtractor,
           "align": AlignedBandExtractor}[extractor]
    return {"features_extractor_class": cls, "features_extractor_kwargs": extractor_kwargs}
