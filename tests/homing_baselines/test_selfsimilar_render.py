"""Rendered self-similar landmarks: perspective views from the env, detection at 2 m
straight on and at 45 degrees, and the ``corridors`` scene."""

import math

import numpy as np
import pytest

from homing_baselines.camera_models import PerspectiveModel
from homing_baselines.selfsimilar_detector import DetectorConfig, detect_landmarks
from homing_gym.scenes import scene_factory
from homing_gym.scenes.base import Scene, square_walls
from homing_gym.scenes.corridors import wall_panel
from homing_gym.selfsimilar import PanelLayout

#: One panel, id 5, centred on the wall x = 3 facing -x.
SCENE = Scene("one_panel", ((-3, -3), (3, 3)), walls=square_walls(6.0, height=1.2),
              landmarks=(wall_panel(5, 3.0, 0.0, math.pi),))


def _viewpoint(distance, angle_deg):
    """A pose ``distance`` m from the panel centre, ``angle_deg`` off its normal, facing it."""
    a = math.radians(angle_deg)
    x, y = 3.0 - distance * math.cos(a), distance * math.sin(a)
    return np.array([x, y, math.atan2(-y, 3.0 - x)])


@pytest.fixture(scope="module")
def env():
    import gymnasium as gym

    import homing_gym

    gym.register_envs(homing_gym)
    e = gym.make("homing_gym/LocalHoming-v0", scene=SCENE, start_distance=(0.3, 1.0))
    e.reset(seed=0)
    yield e.unwrapped
    e.close()


@pytest.mark.parametrize("size,cfg", [((640, 480), DetectorConfig()),
                                      ((320, 240), DetectorConfig(window=22, row_step=3))])
@pytest.mark.parametrize("angle", [0, 45])
def test_detector_finds_a_rendered_landmark_at_2m(env, size, cfg, angle):
    pose = _viewpoint(2.0, angle)
    image = env.render_view(pose, size=size, hfov_deg=60)
    assert image.shape == (size[1], size[0], 3) and image.dtype == np.uint8
    found = detect_landmarks(image, PerspectiveModel.from_fov(*size, math.radians(60)), cfg)
    assert [d.id for d in found] == [5]
    d = found[0]
    # the panel centre is straight ahead; the distance (to the pattern's left edge)
    # within 10% of the true one
    assert abs(d.bearing) < math.radians(1.5)
    layout = PanelLayout()
    left_edge = np.array([3.0, layout.width / 2 - layout.margin])  # as seen from the room
    true = math.dist(pose[:2], left_edge) if angle else 2.0
    assert d.distance == pytest.approx(true, rel=0.1)


def test_render_view_leaves_the_episode_alone(env):
    pose, pano = env.pose.copy(), env.panorama.copy()
    env.render_view(_viewpoint(1.0, 30), size=(160, 120))
    assert np.array_equal(env.pose, pose)
    assert np.array_equal(env.render_panorama(env.sim.robot.pose()), pano)
    with pytest.raises(ValueError, match="width"):
        env.render_view(size=(8, 120))
    with pytest.raises(ValueError, match="hfov"):
        env.render_view(hfov_deg=200)


def test_corridors_scene_has_unique_barcoded_panels():
    scene = scene_factory("corridors").build(np.random.default_rng(0))
    panels = [lm for lm in scene.landmarks if lm.shape == "panel"]
    assert len(panels) >= 8
    ids = sorted(scene.metadata["landmarks"])
    assert ids == list(range(len(panels)))


@pytest.mark.slow
def test_corridors_visibility_graph_is_connected_on_rendered_scans():
    """From each room panel's standing place, a rendered scan (12 views, the controller's
    detector) finds a panel outside the room, from each corridor panel's another
    corridor panel, and every panel can be reached from every other one over the edges
    found (Briggs et al. §4.1)."""
    import gymnasium as gym
    import networkx as nx

    from homing_train.figures.selfsimilar import panel_area, scan_visibility

    e = gym.make("homing_gym/LandmarkNavigation-v0")
    try:
        e.reset(seed=0)
        seen = scan_visibility(e)
        scene = e.unwrapped.scene
    finally:
        e.close()
    ids = set(scene.metadata["landmarks"])
    assert set(seen) == ids
    corridor = len(scene.metadata["rooms"]) - 1          # the last area is the corridor
    for a, bs in seen.items():
        area = panel_area(scene, a)
        assert any(panel_area(scene, b) != area or area == corridor
                   for b in bs if b in ids), (a, bs)
    graph = nx.DiGraph([(a, b) for a, bs in seen.items() for b in bs if b in ids])
    assert set(graph) == ids and nx.is_strongly_connected(graph)
