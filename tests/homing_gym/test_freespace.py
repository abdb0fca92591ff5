"""The world check: free regions of a scene, drawn and counted."""

import numpy as np
import pytest

from homing_gym import freespace
from homing_gym.scenes.base import Scene, Wall
from homing_gym.render.topdown import MapCanvas


def unequal_rooms() -> Scene:
    """6 x 2 m split at x = 1 by a wall from bound to bound: rooms of 4 and 2 m."""
    return Scene("unequal_rooms", ((-3.0, -1.0), (3.0, 1.0)),
                 walls=(Wall((1.0, -1.0), (1.0, 1.0), thickness=0.1),))


def test_free_space_counts_the_regions_largest_first():
    found = freespace.free_space(unequal_rooms(), 0.22)
    assert len(found.region_shares) == 2
    big, small = found.region_shares
    assert big + small == pytest.approx(1.0)
    # free floor: (room length - 2 x 0.22 - half the wall) x (2 - 2 x 0.22) per room
    assert big / small == pytest.approx((4 - 0.44 - 0.05) / (2 - 0.44 - 0.05), rel=0.05)
    assert "2 region(s)" in found.summary()


def test_the_largest_region_is_green_the_other_orange():
    scene = unequal_rooms()
    img = freespace.free_space_image(scene, 0.22, size=300).astype(int)
    canvas = MapCanvas(scene, 300)
    u, v = canvas.px(-1.0, 0.0)
    left = img[v, u]
    u, v = canvas.px(2.0, 0.0)
    right = img[v, u]
    assert left[1] > left[0] and left[1] > left[2]          # green
    assert right[0] > right[1] > right[2]                   # orange


def test_command_writes_both_pictures(tmp_path, capsys):
    assert freespace.main(["--scene", "arena", "--out", str(tmp_path / "check")]) == 0
    assert (tmp_path / "check" / "freespace.png").is_file()
    assert (tmp_path / "check" / "panorama.png").is_file()
    assert "1 region(s): 100.0%" in capsys.readouterr().out


def test_command_refuses_a_file_as_out(tmp_path):
    (tmp_path / "f.txt").write_text("x")
    with pytest.raises(SystemExit):
        freespace.main(["--scene", "arena", "--out", str(tmp_path / "f.txt")])
