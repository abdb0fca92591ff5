"""``warping``: 1-D image warping of Franz, Schölkopf, Mallot & Bülthoff (1998).

"Where did I take that snapshot? Scene-based homing by image matching" (Biol. Cybern.
79:191-202). The robot holds a one-dimensional panoramic snapshot of the horizon taken at
home. Assuming all landmarks lie at the *same distance* from home (the equal-distance
assumption), every displacement of the robot predicts how the snapshot would look from
the displaced place: the snapshot is *warped*. The displacement has three parameters:

* α: direction of the movement from home to the current place (home frame, radians);
* ψ: rotation of the robot's heading relative to the home heading (radians);
* ρ = (distance moved) / (landmark distance), ``0 <= ρ < 1``.

Geometry (landmarks on the unit circle about home): from the displaced place
``P = ρ (cos α, sin α)`` a ray at current-frame bearing φ points along world direction
φ + ψ and meets the circle at ``Q = P + t u``, ``t = -P·u + sqrt((P·u)^2 + 1 - ρ^2)``;
the predicted current pixel at φ shows the snapshot at bearing ``atan2(Q)``
(:func:`warp_bearings`). The parameters of the warped snapshot closest to the current
view give the home direction ``α + π`` in the home frame, ``α + π - ψ`` in the robot frame.

Our choices (documented, not all fixed by the paper):

* 1-D image: the panorama's luminance averaged over ``rows`` rows centred on the
  horizon (the env's ``signature`` construction,
  :func:`homing_gym.render.panorama.signature_weights`),
  then circularly smoothed with a Gaussian of ``smooth_deg``; one sample per column
  (256 = 1.41° for the default panorama).
* Exhaustive search: α in ``n_alpha`` = 72 steps (5°), ρ in ``rho_values`` (0 to 0.95 in
  steps of 0.05), ψ at every column shift (1.41°, all 256): ψ is a circular shift of the
  warped image, so all ψ cost one circular correlation per (α, ρ).
* Image distance: the sum of squared differences (Euclidean distance) between the
  warped snapshot and the current 1-D image.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import lru_cache

import cv2
import numpy as np

from homing_baselines.base import Controller
from homing_baselines.motion import Move
from homing_gym.geometry import wrap_angle
from homing_gym.render.panorama import bearing_column, column_bearing, signature_weights
from homing_gym.vision import horizon_line
from homing_gym.validation import is_real


@dataclass(frozen=True)
class WarpingConfig:
    """Search grid and 1-D image of warping (see the module doc)."""

    n_alpha: int = 72
    rho_values: tuple[float, ...] = tuple(round(0.05 * k, 2) for k in range(20))
    rows: int = 5
    smooth_deg: float = 2.0

    def __post_init__(self) -> None:
        if not (isinstance(self.n_alpha, int) and self.n_alpha >= 4):
            raise ValueError(f"n_alpha must be an integer >= 4, got {self.n_alpha!r}")
        rho = np.asarray(self.rho_values, dtype=np.float64)
        if rho.ndim != 1 or rho.size == 0 or np.any(rho < 0) or np.any(rho >= 1):
            raise ValueError(f"rho_values must be a non-empty sequence in [0, 1), "
                             f"got {self.rho_values!r}")
        if not (isinstance(self.rows, int) and self.rows >= 1):
            raise ValueError(f"rows must be an integer >= 1, got {self.rows!r}")
        if not self.smooth_deg >= 0:
            raise ValueError(f"smooth_deg must be >= 0 degrees, got {self.smooth_deg!r}")


@dataclass
class WarpResult:
    """Best warp parameters (radians; ρ unitless), the home direction in the robot frame,
    the best and the unwarped (ρ = 0, best ψ) image distances."""

    alpha: float
    psi: float
    rho: float
    home_direction: float
    distance: float
    distance_unwarped: float
    scores: np.ndarray = field(repr=False, default=None)


def horizon_image(panorama: np.ndarray, config: WarpingConfig = WarpingConfig()) -> np.ndarray:
    """The 1-D horizon image (W,) float64 in [0, 1] of an RGB uint8 panorama."""
    if panorama.ndim != 3 or panorama.shape[2] != 3:
        raise ValueError(f"panorama must be (H, W, 3), got {panorama.shape}")
    H, W = panorama.shape[:2]
    if config.rows > H - 2:
        raise ValueError(f"rows={config.rows} does not fit a panorama {H} rows high")
    line = horizon_line(panorama, signature_weights(H, config.rows))
    return smooth_ring(line.astype(np.float64), config.smooth_deg)


def smooth_ring(signal: np.ndarray, sigma_deg: float) -> np.ndarray:
    """Circular Gaussian smoothing of a 360° 1-D image (sigma in degrees)."""
    if sigma_deg <= 0:
        return np.asarray(signal, np.float64)
    W = signal.size
    sigma = sigma_deg / 360 * W
    half = int(math.ceil(3 * sigma))
    padded = np.concatenate([signal[-half:], signal, signal[:half]])
    out = cv2.GaussianBlur(padded[None, :], (2 * half + 1, 1), sigma,
                           borderType=cv2.BORDER_REPLICATE)[0]
    return out[half:half + W]


def warp_bearings(phi, alpha: float, rho: float, psi: float = 0.0):
    """Snapshot bearing (home frame) seen at current-frame bearing ``phi`` after moving
    ``rho`` landmark distances in direction ``alpha`` and turning by ``psi`` (radians)."""
    if not 0 <= rho < 1:
        raise ValueError(f"rho must be in [0, 1), got {rho!r}")
    world = np.asarray(phi, np.float64) + psi
    ux, uy = np.cos(world), np.sin(world)
    px, py = rho * math.cos(alpha), rho * math.sin(alpha)
    pu = px * ux + py * uy
    t = -pu + np.sqrt(pu ** 2 + 1 - rho ** 2)
    return np.arctan2(py + t * uy, px + t * ux)


@lru_cache(maxsize=8)
def _warp_tables(width: int, n_alpha: int, rho_values: tuple[float, ...]
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Interpolation tables (ψ = 0): for every (α, ρ) and current column, the two
    snapshot columns and the weight of the second. Shapes (A*P, W)."""
    phi = column_bearing(np.arange(width) + 0.5, width)
    alphas = 2 * np.pi * np.arange(n_alpha) / n_alpha
    src = np.stack([warp_bearings(phi, a, r) for a in alphas for r in rho_values])
    x = bearing_column(src, width) - 0.5  # continuous index in column-centre units
    lo = np.floor(x).astype(np.int64)
    w = x - lo
    return lo % width, (lo + 1) % width, w, alphas


def warp_search(current: np.ndarray, snapshot: np.ndarray,
                config: WarpingConfig = WarpingConfig()) -> WarpResult:
    """Exhaustive search over (α, ψ, ρ) for the warped ``snapshot`` closest (SSD) to the
    ``current`` 1-D image (both (W,) of equal length). Pure function."""
    current = np.asarray(current, np.float64)
    snapshot = np.asarray(snapshot, np.float64)
    if current.shape != snapshot.shape or current.ndim != 1:
        raise ValueError(f"current and snapshot must be 1-D images of equal length, got "
                         f"{current.shape} and {snapshot.shape}")
    W = current.size
    rhos = tuple(float(r) for r in config.rho_values)
    lo, hi, w, alphas = _warp_tables(W, config.n_alpha, rhos)
    warped = snapshot[lo] * (1 - w) + snapshot[hi] * w  # (A*P, W), ψ = 0
    # ψ turns the robot left: the image content moves to lower bearings, i.e. to higher
    # columns; rotating by k columns is a circular shift: warped_psi[x] = warped[x - k].
    # SSD(k) = |w|^2 + |c|^2 - 2 sum_x warped[x - k] c[x]  (circular correlation by FFT)
    corr = np.fft.irfft(np.conj(np.fft.rfft(warped, axis=1)) * np.fft.rfft(current)[None, :],
                        n=W, axis=1)
    ssd = (warped ** 2).sum(1)[:, None] + (current ** 2).sum() - 2 * corr  # (A*P, W)
    scores = ssd.reshape(config.n_alpha, len(rhos), W)
    a, r, k = np.unravel_index(int(np.argmin(scores)), scores.shape)
    psi = wrap_angle(2 * np.pi * k / W)
    alpha = float(alphas[a])
    rho = rhos[r]
    zero = [i for i, v in enumerate(rhos) if v == 0.0]
    unwarped = float(scores[:, zero[0]].min()) if zero else math.nan
    return WarpResult(alpha=wrap_angle(alpha), psi=psi, rho=rho,
                      home_direction=wrap_angle(alpha + np.pi - psi),
                      distance=float(scores[a, r, k]), distance_unwarped=unwarped,
                      scores=scores)


def warping_homing(current: np.ndarray, goal: np.ndarray,
                   config: WarpingConfig = WarpingConfig()) -> tuple[float, float, WarpResult]:
    """Pure function: (current panorama, goal panorama) -> (home direction in the robot
    frame, rotation ψ relative to the home heading, diagnostics)."""
    result = warp_search(horizon_image(current, config), horizon_image(goal, config), config)
    return result.home_direction, result.psi, result


@dataclass
class WarpingController(Controller):
    """Franz et al. 1998 homing from ``panorama`` and ``goal``: each decision searches the
    warp parameters and moves ``step_length`` m in the home direction; it stops when the
    best warp is the identity displacement (ρ = 0), i.e. the views match unwarped.
    Search resolution: ``n_alpha`` directions, ρ from 0 to ``rho_max`` in ``n_rho`` values."""

    step_length: float = 0.1
    n_alpha: int = 72
    n_rho: int = 20
    rho_max: float = 0.95
    smooth_deg: float = 2.0

    def validate(self) -> None:
        if not (is_real(self.step_length)
                and self.step_length > 0):
            raise ValueError(f"warping: step_length must be positive metres, "
                             f"got {self.step_length!r}")
        if not (isinstance(self.n_rho, int) and self.n_rho >= 2 and 0 < self.rho_max < 1):
            raise ValueError(f"warping: need an integer n_rho >= 2 and 0 < rho_max < 1, got "
                             f"n_rho={self.n_rho!r}, rho_max={self.rho_max!r}")
        self.config = WarpingConfig(
            n_alpha=self.n_alpha, smooth_deg=self.smooth_deg,
            rho_values=tuple(float(v) for v in np.linspace(0, self.rho_max, self.n_rho)))

    def on_reset(self) -> None:
        self._goal_image: np.ndarray | None = None
        self.last_result: WarpResult | None = None

    def decide(self, observation) -> Move | None:
        goal = observation["goal"]
        if self.is_new_goal(goal):              # a new target: a new snapshot
            self._goal_image = horizon_image(goal, self.config)
        result = warp_search(horizon_image(observation["panorama"], self.config),
                             self._goal_image, self.config)
        self.last_result = result
        if result.rho == 0.0:
            return None
        return Move(result.home_direction, self.step_length)
