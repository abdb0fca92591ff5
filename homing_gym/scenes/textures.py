"""Textures shipped as package data, and the procedural generator that made them.

The PNGs in ``homing_gym/assets/textures`` are produced deterministically by
``python -m homing_gym.scenes.textures`` (seeded), so they can be regenerated and reviewed.
"""

from __future__ import annotations

from functools import lru_cache
from importlib import resources
from pathlib import Path

import cv2
import numpy as np

TEXTURE_DIR = Path(str(resources.files("homing_gym") / "assets" / "textures"))


def available_textures() -> list[str]:
    """Names of the shipped textures."""
    return sorted(p.stem for p in TEXTURE_DIR.glob("*.png"))


def texture_path(texture: str) -> str:
    """File path of a texture given by shipped name or by path to a PNG file."""
    if (TEXTURE_DIR / f"{texture}.png").is_file():
        return str(TEXTURE_DIR / f"{texture}.png")
    if texture.endswith(".png") and Path(texture).is_file():
        return texture
    raise ValueError(
        f"unknown texture {texture!r}; allowed: a path to a .png file or one of "
        f"{available_textures()}")


@lru_cache(maxsize=256)
def load_texture(texture: str) -> np.ndarray:
    """The texture's pixels, uint8 RGB ``(h, w, 3)``, row 0 at the top (cached; treat as
    read-only)."""
    path = texture_path(texture)
    image = cv2.imread(path, cv2.IMREAD_COLOR)
    if image is None:
        raise ValueError(f"texture {texture!r}: {path} is not a readable image")
    rgb = cv2.cvtColor(image, cv2.COLOR_BGR2RGB)
    rgb.setflags(write=False)
    return rgb


def check_texture(texture: str) -> None:
    """Raise ``ValueError`` if ``texture`` names no shipped texture or PNG file."""
    texture_path(texture)


def _noise(rng: np.random.Generator, size: int, scale: int) -> np.ndarray:
    small = rng.random((max(size // scale, 2), max(size // scale, 2)))
    return cv2.resize(small, (size, size), interpolation=cv2.INTER_CUBIC)


def _bricks(rng, size, base, mortar=(200, 200, 195)):
    img = np.empty((size, size, 3), np.float64)
    img[:] = mortar
    rows, cols = 8, 4
    bh, bw = size // rows, size // cols
    for r in range(rows):
        offset = (bw // 2) * (r % 2)
        for c in range(-1, cols + 1):
            x0 = c * bw + offset + 2
            tint = np.asarray(base) * rng.uniform(0.75, 1.15)
            img[r * bh + 2:(r + 1) * bh - 2, max(x0, 0):max(min(x0 + bw - 4, size), 0)] = tint
    return img


def _stripes(rng, size, colors, vertical):
    img = np.empty((size, size, 3), np.float64)
    edges = np.sort(rng.integers(0, size, len(colors) * 2))
    idx = np.searchsorted(edges, np.arange(size)) % len(colors)
    band = np.asarray(colors, np.float64)[idx]
    img[:] = band[None, :, :] if vertical else band[:, None, :]
    return img


def _checker(size, n, a, b):
    ii, jj = np.meshgrid(np.arange(size) * n // size, np.arange(size) * n // size)
    return np.where(((ii + jj) % 2 == 0)[..., None], np.asarray(a, float), np.asarray(b, float))


def _wood(rng, size, base):
    y = np.linspace(0, 1, size)[:, None]
    grain = np.sin(2 * np.pi * (12 * y + 3 * _noise(rng, size, 16)))
    shade = 0.8 + 0.2 * grain
    return shade[..., None] * np.asarray(base, float)


def _poster(rng, size):
    img = np.full((size, size, 3), 235.0)
    for _ in range(6):
        color = rng.integers(20, 230, 3)
        center = tuple(int(v) for v in rng.integers(size // 8, size - size // 8, 2))
        if rng.random() < 0.5:
            cv2.circle(img, center, int(rng.integers(size // 12, size // 4)), color.tolist(), -1)
        else:
            half = rng.integers(size // 12, size // 4, 2)
            cv2.rectangle(img, tuple(int(v) for v in np.subtract(center, half)),
                          tuple(int(v) for v in np.add(center, half)), color.tolist(), -1)
    return img


def generate_textures(size: int = 128, seed: int = 7) -> dict[str, np.ndarray]:
    """All shipped textures as uint8 RGB arrays, keyed by name (deterministic)."""
    rng = np.random.default_rng(seed)
    tex = {
        "bricks_red": _bricks(rng, size, (150, 60, 45)),
        "bricks_grey": _bricks(rng, size, (120, 120, 125)),
        "stripes_warm": _stripes(rng, size, [(230, 180, 60), (200, 80, 40), (250, 240, 220)], True),
        "stripes_cool": _stripes(rng, size, [(60, 110, 190), (200, 220, 240), (40, 60, 90)], False),
        "checker_green": _checker(size, 8, (60, 140, 70), (220, 230, 210)),
        "checker_dark": _checker(size, 4, (40, 40, 50), (170, 160, 140)),
        "wood_light": _wood(rng, size, (200, 160, 110)),
        "wood_dark": _wood(rng, size, (120, 80, 50)),
        "poster_a": _poster(rng, size),
        "poster_b": _poster(rng, size),
        "concrete": np.repeat(128 + 60 * (_noise(rng, size, 8) - 0.5)[..., None]
                              + 25 * (_noise(rng, size, 32) - 0.5)[..., None], 3, axis=2),
        "floor_tiles": _checker(size, 4, (150, 150, 145), (135, 135, 130)),
    }
    return {k: np.clip(v, 0, 255).astype(np.uint8) for k, v in tex.items()}


def main(argv: list[str] | None = None) -> int:
    """Regenerate the shipped texture PNGs (``--out DIR`` writes them elsewhere)."""
    from homing_gym.cli import command_parser
    parser = command_parser("python -m homing_gym.scenes.textures", __doc__)
    parser.add_argument("--out", type=Path, default=TEXTURE_DIR,
                        help="folder to write the PNGs to (default: the package's own)")
    out = parser.parse_args(argv).out
    out.mkdir(parents=True, exist_ok=True)
    for name, img in generate_textures().items():
        cv2.imwrite(str(out / f"{name}.png"), img[..., ::-1])
        print(f"wrote {out / name}.png")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
