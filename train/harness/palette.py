"""One colour per method in every plot, from colour-blind-safe palettes.

Known methods have fixed colours (Okabe & Ito's eight, Paul Tol's muted set and two of
his bright set, then ColorBrewer's dark brown, dark green and dark purple); any other
name (a user's controller or policy) gets a colour from the rest, chosen by a stable
hash of the name, so it is the same in every plot and run. Home and start markers use shapes and colours outside these (:data:`HOME_MARK`,
:data:`START_MARK`).
"""

from __future__ import annotations

import zlib

#: Okabe & Ito (2008), Tol's muted scheme (and his bright blue and yellow),
#: ColorBrewer's BrBG dark brown and PRGn dark green and dark purple, RGB in [0, 1].
_HEX = {"black": "000000", "orange": "E69F00", "sky": "56B4E9", "green": "009E73",
        "blue": "0072B2", "vermillion": "D55E00", "purple": "CC79A7", "grey": "999999",
        "indigo": "332288", "teal": "44AA99", "olive": "999933", "wine": "882255",
        "rose": "CC6677", "sand": "DDCC77", "brown": "8C510A", "forest": "1B7837",
        "plum": "762A83", "cyan": "88CCEE", "tol-green": "117733", "tol-purple": "AA4499",
        "tol-blue": "4477AA", "tol-yellow": "CCBB44"}
_FIXED = {"oracle": "black", "random": "grey", "snapshot": "orange", "warping": "sky",
          "distance": "blue", "bearing": "purple", "bearing-basic": "rose",
          "bearing-complementary": "wine", "bearing-longrange": "indigo",
          "selfsimilar": "olive", "multires": "teal",
          "alv": "tol-purple", "did": "cyan", "min-warping": "tol-green",
          "perfect-memory": "tol-blue", "infomax": "tol-yellow",
          # the shipped learned policies (train/shipped/)
          "ppo_procedural_long": "plum", "ppo_procedural_imitation": "green"}
_SPARE = ("vermillion", "sand", "brown", "forest")
#: Marker colours of the maps (RGB 0-255), used by no method: home a dark navy ring, the
#: start a light grey ring.
HOME_MARK = (20, 20, 120)
START_MARK = (170, 170, 170)


def _rgb(name: str) -> tuple[float, float, float]:
    code = _HEX[name]
    return tuple(int(code[i:i + 2], 16) / 255 for i in (0, 2, 4))


def method_color(method: str) -> tuple[float, float, float]:
    """The RGB colour (0-1) of ``method`` in every plot (fixed for the package's methods
    and shipped policies, else chosen by a hash of the name)."""
    if method in _FIXED:
        return _rgb(_FIXED[method])
    return _rgb(_SPARE[zlib.crc32(method.encode()) % len(_SPARE)])


def method_color_255(method: str) -> tuple[int, int, int]:
    """:func:`method_color` in 0-255 (for OpenCV drawings)."""
    return tuple(int(round(255 * c)) for c in method_color(method))
