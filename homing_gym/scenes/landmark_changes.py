"""Random changes to a scene's landmark panels: some removed, some partly occluded.

Briggs et al. 2000 §4.2-4.3 plan around landmarks that are no longer visible
("lighting, moving obstacles, and changes in viewpoint"; "added or removed landmarks").
:func:`changed_landmarks` draws such a change per episode for ``LandmarkNavigation-v0``
(``remove_landmarks``, ``occlude_landmarks``).
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from homing_gym.scenes.base import Landmark, Scene

#: The occluder: a dark board standing on the floor in front of a panel (metres).
OCCLUDER_WIDTH, OCCLUDER_DEPTH, OCCLUDER_HEIGHT = 0.3, 0.05, 0.8
OCCLUDER_OFFSET = 0.3
OCCLUDER_COLOR = (0.3, 0.3, 0.32, 1.0)


def changed_landmarks(scene: Scene, rng: np.random.Generator, remove: float,
                      occlude: float) -> Scene:
    """``scene`` with each panel of ``metadata["landmarks"]`` removed with probability
    ``remove`` (never all of them), and each remaining one occluded with probability
    ``occlude`` by a board ``OCCLUDER_WIDTH`` m wide standing ``OCCLUDER_OFFSET`` m in
    front of it, shifted sideways uniformly within the panel's half width (so it hides
    a random part). Removed panels leave ``metadata["landmarks"]``."""
    for name, value in (("remove", remove), ("occlude", occlude)):
        if not (0 <= value <= 1):
            raise ValueError(f"{name} probability must be in [0, 1], got {value!r}")
    panels = dict(scene.metadata["landmarks"])
    ids = sorted(panels)
    gone = {i for i in ids if rng.random() < remove}
    if len(gone) == len(ids):
        gone.discard(ids[int(rng.integers(len(ids)))])
    keep = {i: panels[i] for i in ids if i not in gone}
    names = {f"selfsimilar{i}" for i in gone}
    landmarks: list[Landmark] = [lm for lm in scene.landmarks if lm.name not in names]
    for i, (x, y, normal) in keep.items():
        if rng.random() >= occlude:
            continue
        panel = next(lm for lm in scene.landmarks if lm.name == f"selfsimilar{i}")
        side = float(rng.uniform(-0.5, 0.5)) * panel.extent[0] / 2
        tx, ty = -math.sin(normal), math.cos(normal)
        cx = x + OCCLUDER_OFFSET * math.cos(normal) + side * tx
        cy = y + OCCLUDER_OFFSET * math.sin(normal) + side * ty
        landmarks.append(Landmark((cx, cy), shape="box",
                                  extent=(OCCLUDER_WIDTH, OCCLUDER_DEPTH),
                                  height=OCCLUDER_HEIGHT, yaw=normal - math.pi / 2,
                                  color=OCCLUDER_COLOR, name=f"occluder{i}"))
    return replace(scene, landmarks=tuple(landmarks),
                   metadata={**scene.metadata, "landmarks": keep})
