"""The ``selfsimilar`` controller (Briggs et al. 2000 §4): registry and bad input, a
real episode to a visible goal in ``corridors``, and replanning around a removed
landmark in a small fake world (detections from geometry, exact odometry)."""

import math
from dataclasses import dataclass, field

import numpy as np
import pytest

import homing_baselines
import homing_baselines.selfsimilar as selfsimilar
from homing_baselines.motion import Move
from homing_baselines.selfsimilar_detector import Detection
from homing_baselines.selfsimilar_panel import PanelPose
from homing_gym.geometry import wrap_angle
from homing_gym.tasks.landmark_navigation import N_IDS
from homing_train.harness.evaluate import run_episode


def test_registered_with_its_observation_keys_and_checks_its_parameters():
    c = homing_baselines.make("selfsimilar", planning="probabilistic")
    assert isinstance(c, selfsimilar.SelfSimilarController)
    assert c.observation_keys() == ("view", "goal_id", "odometry")
    with pytest.raises(ValueError, match="planning 'astar'.*deterministic"):
        homing_baselines.make("selfsimilar", planning="astar")
    with pytest.raises(ValueError, match="scan_step_deg"):
        homing_baselines.make("selfsimilar", scan_step_deg=90.0)
    with pytest.raises(ValueError, match="standoff"):
        homing_baselines.make("selfsimilar", standoff=0.0)
    with pytest.raises(ValueError, match="odometry"):
        c.decide({"view": np.zeros((240, 320, 3), np.uint8),
                  "goal_id": np.eye(N_IDS, dtype=np.float32)[0]})


def test_reaches_a_visible_goal_and_stops_in_front_of_it(make_env, controller_for):
    """Corridor, 2 m in front of panel 9 (east end wall), looking 70 degrees away from
    it: the robot must scan, find it, servo and stop in front of it
    (``success_on="stop"``: a success only if its own stop is in the success region)."""
    env = make_env("homing_gym/LandmarkNavigation-v0", success_on="stop",
                   obs_keys=("view", "goal_id", "odometry"), max_episode_steps=250)
    env.reset(seed=5)
    assert env.unwrapped.task.goal_id == 9
    record = run_episode(env, controller_for("selfsimilar", env), seed=5, start=[6.0, 3.0, 1.2])
    assert record.success and record.terminated
    assert record.path_length < 3.0


@dataclass
class FakeWorld:
    """Landmark panels ``{id: (x, y, normal)}`` seen from in front within ``reach`` m
    and the field of view; exact motion and odometry."""

    panels: dict[int, tuple[float, float, float]]
    pose: np.ndarray = field(default_factory=lambda: np.zeros(3))
    reach: float = 3.1
    hfov: float = math.radians(60)

    def visible(self, pose) -> dict[int, tuple[float, float]]:
        """Distance and world angle of each panel visible from ``pose`` (any heading)."""
        out = {}
        for i, (x, y, normal) in self.panels.items():
            dx, dy = x - pose[0], y - pose[1]
            if math.hypot(dx, dy) <= self.reach and dx * math.cos(normal) + dy * math.sin(
                    normal) < 0:
                out[i] = (math.hypot(dx, dy), math.atan2(dy, dx))
        return out

    def detections(self, *_args) -> list[Detection]:
        out = []
        for i, (distance, angle) in self.visible(self.pose).items():
            bearing = wrap_angle(angle - self.pose[2])
            if abs(bearing) < self.hfov / 2:
                out.append(Detection(i, 0, 0, 0, 0, 0, 1.0, 0, bearing, distance, 1.0, 5))
        return out

    def panel_pose(self, _gray, det: Detection, *_args) -> PanelPose:
        x, y, normal = self.panels[det.id]
        c, s = math.cos(self.pose[2]), math.sin(self.pose[2])
        dx, dy = x - self.pose[0], y - self.pose[1]
        return PanelPose((c * dx + s * dy, -s * dx + c * dy), wrap_angle(normal - self.pose[2]))

    def move(self, move: Move) -> None:
        self.pose[2] = wrap_angle(self.pose[2] + move.direction)
        self.pose[:2] += move.distance * np.array([math.cos(self.pose[2]),
                                                    math.sin(self.pose[2])])

    def observation(self, goal: int) -> dict[str, np.ndarray]:
        """A random view for each pose (the same view where the robot did not move)."""
        key = tuple(int(round(v * 1000)) for v in self.pose)
        view = np.random.default_rng([k % 2**32 for k in key]).integers(
            0, 256, (240, 320, 3), dtype=np.uint8)
        return {"view": view, "odometry": self.pose.copy(),
                "goal_id": np.eye(N_IDS, dtype=np.float32)[goal]}


#: Panels whose standing places (1 m out) are (0, 0), (2, 0), (1, 1.5) and (3, 1.5).
#: The goal 2 is out of reach from 0; 0 -> 1 -> 2 (4.7 m) is shorter than 0 -> 3 -> 2.
PANELS = {0: (-1.0, 0.0, 0.0), 1: (2.0, -1.0, math.pi / 2),
          3: (1.0, 2.5, -math.pi / 2), 2: (4.0, 1.5, math.pi)}


def _standing(i: int) -> tuple[float, float]:
    x, y, normal = PANELS[i]
    return x + math.cos(normal), y + math.sin(normal)


def _controller(monkeypatch, world: FakeWorld, planning: str):
    """A controller seeing ``world``, standing at landmark 0 (world origin, facing away
    from it; its own frame is the world's)."""
    monkeypatch.setattr(selfsimilar, "detect_landmarks", world.detections)
    monkeypatch.setattr(selfsimilar, "panel_pose", world.panel_pose)
    c = homing_baselines.make("selfsimilar", planning=planning)
    c.reset(seed=0)
    c.at = 0
    return c


def _run(c, world: FakeWorld, goal: int = 2) -> list[int]:
    """Decide and move until the controller stops; the landmarks it stood at."""
    visited = [0]
    for _ in range(300):
        move = c.decide(world.observation(goal))
        if c.at is not None and c.at != visited[-1]:
            visited.append(c.at)
        if move is None:
            break
        world.move(move)
    return visited


def _navigate(monkeypatch, removed: set[int], planning: str):
    """The robot at landmark 0 with the graph learnt when every landmark was there;
    those in ``removed`` are gone now. Returns the landmarks it stood at, in order,
    the controller and the world."""
    world = FakeWorld({i: p for i, p in PANELS.items() if i not in removed})
    c = _controller(monkeypatch, world, planning)
    everything = FakeWorld(PANELS)
    for a in (0, 1, 3):
        c.graph.observe(a, everything.visible(_standing(a)))
    c.explored.update({0, 1, 3})
    return _run(c, world), c, world


@pytest.mark.parametrize("planning", ["deterministic", "probabilistic"])
def test_replans_around_a_removed_landmark(monkeypatch, planning):
    visited, _, world = _navigate(monkeypatch, set(), planning)
    assert visited == [0, 1, 2]
    visited, c, world = _navigate(monkeypatch, {1}, planning)
    assert visited == [0, 3, 2]
    assert not c.graph.edge(0, 1).visible and c.graph.edge(0, 1).probability < 1
    assert math.dist(world.pose[:2], _standing(2)) < 0.15
    assert c.graph.edge(3, 2).travelled == pytest.approx(
        math.dist(_standing(3), _standing(2)), abs=0.3)


@pytest.mark.parametrize("planning", ["deterministic", "probabilistic"])
def test_dead_reckons_to_remembered_landmarks_when_the_goal_is_out_of_reach(monkeypatch,
                                                                           planning):
    """§4.2: nothing is visible from landmark 0 now (short sight), but 3, with an edge
    to the goal 2, and 2 were seen before: the robot drives to 3 by its remembered
    position, and, 2 not being visible from 3 either, on to 2 the same way."""
    world = FakeWorld(PANELS, reach=2.0)
    c = _controller(monkeypatch, world, planning)
    c.graph.observe(3, FakeWorld(PANELS).visible(_standing(3)))
    c.explored.add(3)
    c.positions.update({i: np.array(PANELS[i][:2]) for i in (2, 3)})
    assert _run(c, world) == [0, 3, 2]
    assert math.dist(world.pose[:2], _standing(2)) < 0.15


def test_a_blocked_drive_backs_off_and_side_steps(monkeypatch):
    """A drive that leaves the view unchanged ran into something: back off, side-step."""
    world = FakeWorld(PANELS)
    c = _controller(monkeypatch, world, "deterministic")
    c.at = None
    c.positions[3] = np.array(PANELS[3][:2])
    move = c._reckon_to({3})                  # turn towards 3, then drive
    world.move(move)
    drive = c.decide(world.observation(2))
    assert drive.distance > 0                 # the wall: the robot does not move
    # back off (a turn and then the drive, made apart), then side-step
    for expected in (Move(math.pi, 0.0), Move(0.0, selfsimilar.SIDESTEP),
                     Move(math.pi / 2, 0.0), Move(0.0, selfsimilar.SIDESTEP)):
        move = c.decide(world.observation(2))
        assert move == expected
        world.move(move)


def _episode(c, world: FakeWorld, start, goal: int) -> list[int]:
    """Reset the controller, put the robot at ``start`` (world frame) and run to the
    goal; the landmarks it stood at."""
    c.reset(seed=int(100 * start[0]))
    world.pose = np.array(start, dtype=float)
    visited = []
    for _ in range(400):
        move = c.decide(world.observation(goal))
        if c.at is not None and c.at not in visited[-1:]:
            visited.append(c.at)
        if move is None:
            break
        world.move(move)
    return visited


def _in_frame(origin, pose) -> np.ndarray:
    """``pose`` (world) in the frame of a robot switched on at ``origin``."""
    c, s = math.cos(origin[2]), math.sin(origin[2])
    dx, dy = pose[0] - origin[0], pose[1] - origin[1]
    return np.array([c * dx + s * dy, -s * dx + c * dy, wrap_angle(pose[2] - origin[2])])


@pytest.mark.parametrize("planning", ["deterministic", "probabilistic"])
def test_the_map_persists_across_the_episodes_of_a_world(monkeypatch, planning):
    """memory="world": the second episode starts elsewhere, its odometry in a frame of its
    own; the robot goes to landmark 0, where it stood in the first episode, takes that
    anchor's pose (its pose is in the first episode's frame from then on) and the graph
    goes on counting looks. memory="episode" starts afresh in the new frame."""
    first, second = (0.5, 0.3, 0.4), (0.3, -0.3, 2.5)
    for memory in ("world", "episode"):
        world = FakeWorld(PANELS)
        monkeypatch.setattr(selfsimilar, "detect_landmarks", world.detections)
        monkeypatch.setattr(selfsimilar, "panel_pose", world.panel_pose)
        c = homing_baselines.make("selfsimilar", planning=planning, memory=memory)
        assert _episode(c, world, first, goal=2) == [0, 1, 2]
        assert c.graph.edge(0, 1).looked == 1
        assert _episode(c, world, second, goal=2) == [0, 1, 2]
        origin = first if memory == "world" else second
        assert np.allclose(c._pose, _in_frame(origin, world.pose), atol=0.15)
        assert c.graph.edge(0, 1).looked == (2 if memory == "world" else 1)
    with pytest.raises(ValueError, match="memory 'forever'"):
        homing_baselines.make("selfsimilar", memory="forever")


def test_the_harness_names_the_world_and_each_world_keeps_its_own_map(make_env,
                                                                       controller_for):
    """The harness prepares the controller with its env: the controller notes the scene's
    name (and keeps no handle on the env); resets keep that world's map, another world
    gets another, and memory="episode" starts every episode afresh."""
    env = make_env("homing_gym/LandmarkNavigation-v0",
                   obs_keys=("view", "goal_id", "odometry"))
    c = controller_for("selfsimilar", env)
    c.reset(seed=0)
    assert c._world == "corridors" and not any(v is env for v in vars(c).values())
    corridors = c.graph
    corridors.observe(0, {1: (2.0, 0.5)})
    c.reset(seed=1)
    assert c.graph is corridors and c.graph.edge(0, 1).looked == 1
    c._world = "elsewhere"
    c.reset(seed=2)
    assert c.graph is not corridors and c.graph.graph.number_of_nodes() == 0
    c._world = "corridors"
    c.reset(seed=3)
    assert c.graph is corridors
    fresh = homing_baselines.make("selfsimilar", memory="episode")
    fresh.reset(seed=0)
    first = fresh.graph
    first.observe(0, {1: (2.0, 0.5)})
    fresh.reset(seed=1)
    assert fresh.graph is not first and fresh.graph.edge(0, 1) is None


def test_a_procedural_scene_is_refused_by_the_world_memory_and_taken_per_episode(
        make_env, controller_for):
    """A procedural scene draws another world under the same name: a map kept by name
    would be carried into a different world, so memory="world" refuses it; memory="episode"
    runs there."""
    from homing_gym.scenes import SceneFactory, corridors_scene

    drawn_anew = SceneFactory(build=lambda rng: corridors_scene(), randomised=True)
    env = make_env("homing_gym/LandmarkNavigation-v0", scene=drawn_anew,
                   obs_keys=("view", "goal_id", "odometry"))
    assert env.unwrapped.draws_worlds
    with pytest.raises(ValueError, match="memory='world'.*draws a new world.*memory='episode'"):
        controller_for("selfsimilar", env)
    controller_for("selfsimilar", env, memory="episode").reset(seed=0)
    fixed = make_env("homing_gym/LandmarkNavigation-v0", obs_keys=("view", "goal_id", "odometry"))
    assert not fixed.unwrapped.draws_worlds
