"""``selfsimilar``: landmark navigation with self-similar landmarks and a visibility graph
(Briggs, Scharstein et al. 2000, §4).

The robot knows the landmark design, not the map. It builds the map, a
:class:`~homing_baselines.selfsimilar_graph.VisibilityGraph` with landmark positions, in a
global frame of its own: where it was first switched on, heading 0 (§4.1). With
``memory="world"`` (the default: the paper explores once and then navigates, §4, and
§4.3's probabilities come from "the history of observations") the map persists across the
episodes of one world (:meth:`SelfSimilarController.check_env`: the env's scene, by name):
the graph with its look/seen counts and travelled distances, the landmarks scanned from,
their last known positions, and the pose in which the robot first stood in front of each
landmark (its *anchor*). A new episode starts somewhere unknown, so the robot is not
localised: it goes to the nearest visible anchor (the goal if seen), takes the anchor's
pose as its own when standing there, scans and recalibrates its heading against the
stored angles (§4.1), and carries what it learnt on the way (graph updates held back,
landmark positions) into the map frame. With ``memory="episode"`` each episode starts
with an empty map. It reads only the observation:

* ``view``: the forward perspective camera (the paper's camera; the default panorama is
  far too coarse for the detector, see ``docs/selfsimilar.md``), searched by
  :func:`~homing_baselines.selfsimilar_detector.detect_landmarks` at every decision;
* ``goal_id``: the one-hot goal landmark;
* ``odometry``: wheel odometry. Only its *increments* between decisions are used (dead
  reckoning of the robot's own pose and the travelled distance of §4.1); its absolute
  value is expressed in the goal's frame by the env and is never read as such.

What it does (the modes of §4):

1. **Scan** (§4.1: "when at a landmark, scan for all visible landmarks"): turn on the
   spot in ``scan_step_deg`` steps through a full turn, detecting in each view; each
   landmark seen gets the distance from its apparent size and the global angle (robot
   heading + bearing) from its most central view.
2. **Away from any landmark** (the start, or after losing its way) it scans and goes to
   the goal if it saw it, else to the nearest landmark seen (§4.2: "it moves to the
   nearest visible landmark"), preferring ones it has not scanned from; with nothing
   in sight it dead-reckons as at a landmark (3), and only with no landmark to go to
   drives ``wander_distance`` in a random direction (seeded by the episode) and scans
   again.
3. **At landmark A** (after servoing to its standing place): the scan result updates
   the graph (:meth:`VisibilityGraph.observe`: edges with distance, angle, looked/seen
   counts). Then
   *deterministic* (§4.2): plan the shortest path to the goal over the edges believed
   visible; turn to the direction where the next landmark is expected and look; if it is
   not there, mark the edge invisible and replan;
   *probabilistic* (§4.3): with ``E`` the expected shortest lengths (value iteration,
   stay cost ``look_cost``), head for the visible landmark minimising ``l_Ay + E_y``, or
   stay and scan again.
   If the goal is not reachable from A in the graph: **dead reckoning** (§4.2, "the robot
   uses dead reckoning to navigate to the closest landmark from which the destination
   is reachable"): every landmark seen has a position in the robot's own frame (from
   the pose, the global angle and the distance of its sightings, refined while
   servoing); the robot drives towards the closest landmark (straight-line distance)
   from which the goal is reachable, the goal itself included once seen, until it sees
   it and servos to it. If there is none: explore (§4.1), i.e. go to the closest
   landmark not scanned from yet, by edge lengths plus ``look_cost`` per landmark on
   the way, hop by hop as in navigation; if every landmark of the graph was scanned
   from, dead-reckon to the closest one known that was not.
4. **Visual servoing** to a landmark: detect it in every view, measure the panel's
   centre and normal (:func:`~homing_baselines.selfsimilar_panel.panel_pose`) and step
   towards its standing place ``standoff`` m out along the normal, facing it; the
   edge driven is annotated with the distance travelled (§4.1). A landmark out of view
   is turned to (its last position by dead reckoning); one not found where it should be
   is searched for by a scan; if the scan does not find it either the robot is away
   from any landmark again (2).
5. **Blocked** (no obstacle sensor; §4 leaves local obstacle avoidance to the robot's
   sensors): a drive after which the view has hardly changed (``BLOCKED_CHANGE``; the
   wheels slip, so the odometry cannot tell) ran into a wall or door frame; the robot
   backs off ``SIDESTEP`` m, side-steps as far (to the left and right alternately) and
   servos on; after ``MAX_BLOCKS`` blocked drives in a row it scans.
6. **Finish**: at the goal's standing place it stops (``None``); should the env not have
   ended the episode (its success test is stricter than the estimate), it servos again,
   at most ``MAX_REFINES`` times, then stops for good.

Choices where the paper is silent (also in ``docs/selfsimilar.md``):

* *The standing place* "in front of A at a fixed distance" (§4.1): ``standoff`` = 1.0 m
  out along the panel's normal, facing the panel, inside the env's success region.
  Far away (beyond ``far`` m) the robot approaches along the line of sight; closer it
  aims at a point ``max(standoff, 0.6 d)`` out along the normal (``d`` its distance to
  the panel), a funnel that brings it onto the normal as it closes in.
* *Scan at known landmarks*: the deterministic variant scans fully only at landmarks not
  scanned from before and otherwise only looks where it expects the next landmark (as
  §4.2 says); the probabilistic variant scans at every landmark, because §4.3 decides on
  "the subset of the landmarks currently visible" and counts every look.
* *Heading recalibration* (§4.1 "uses previously obtained landmark visibility
  information to recalibrate its direction"): at a landmark scanned from before, the
  heading is corrected by the mean difference between the stored and the measured
  global angles of the landmarks seen again (if it is below ``MAX_RECALIBRATION``).
* *Dead reckoning* (§4.2) also serves exploration (to an unexplored landmark not
  reachable over the graph) and a robot that sees nothing. A landmark not found where
  dead reckoning puts it is not tried again until the robot next reaches a landmark.
  The robot has no obstacle sensor: a straight dead-reckoned leg may run into a wall.
* *Costs*: edge lengths are metres; ``look_cost`` (m) is both the scan time of §4.1's
  exploration distance and the stay cost ``l_xx`` of §4.3.
* *Relocalisation across episodes* (``memory="world"``; the paper's robot is switched on
  once): the robot's pose at a landmark's standing place is about the same every time
  (within the servoing tolerance, ``ARRIVE_DISTANCE`` and ``ARRIVE_ANGLE``), so the pose
  of its first arrival there is kept as the landmark's anchor and taken as the pose on
  every later arrival (with either memory: within an episode dead reckoning drifts by
  metres, since the wheels slip against walls and turns made in contact do not happen);
  when the robot was not localised, the full scan that follows recalibrates the heading
  (§4.1). Until then the robot plans nothing over the graph (its angles are in the map
  frame): it goes from landmark to landmark as from nowhere, preferring anchors, and
  dead-reckons only to landmarks seen in this episode. A world is named by its scene: the
  harness builds one controller per worker process, so with ``--workers 1`` the
  episodes of a run form one sequence in one map; with more workers each keeps its own
  map of the episodes it happens to get.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import ClassVar

import networkx as nx
import numpy as np

from homing_baselines.base import Controller
from homing_baselines.camera_models import PerspectiveModel
from homing_baselines.motion import Move
from homing_baselines.selfsimilar_detector import Detection, DetectorConfig, detect_landmarks, to_gray
from homing_baselines.selfsimilar_graph import VisibilityGraph
from homing_baselines.selfsimilar_panel import panel_pose
from homing_gym.geometry import wrap_angle
from homing_gym.validation import require_positive

PLANNING = ("deterministic", "probabilistic")
MEMORY = ("world", "episode")
#: Times the robot servos again at the goal when the episode did not end.
MAX_REFINES = 3
#: Scans at one landmark before the robot gives up on it and wanders off.
MAX_SCANS_HERE = 3
#: Views in a row without the servo target before it is searched for by a scan.
MAX_MISSES = 2
#: Largest heading correction (radians) a recalibration may make.
MAX_RECALIBRATION = math.radians(30)
#: Distance (m) to the standing place and angle (rad) to the panel at which it is reached.
ARRIVE_DISTANCE, ARRIVE_ANGLE = 0.12, math.radians(10)
#: A drive after which the view changed by less than this mean absolute intensity
#: ([0, 1]) ran into something (the wheels slip, so odometry does not tell; drives of
#: 0.5 m change rendered views by 0.03-0.2, a blocked robot's by 0.01-0.02); the robot
#: then backs off ``SIDESTEP`` m and side-steps as far, at most ``MAX_BLOCKS`` times in
#: a row before it gives up its target and scans.
BLOCKED_CHANGE, SIDESTEP, MAX_BLOCKS = 0.025, 0.3, 4
#: A move that turns by more than this (radians) before driving is made as two, the turn
#: and then the drive, so that the view before the drive tells whether it was blocked.
SPLIT_TURN = math.radians(5)


@dataclass
class Sighting:
    """A landmark seen during a scan: ``distance`` (m), global ``angle`` (rad) and the
    ``offset`` (rad) of the view it was measured in from the image centre."""

    distance: float
    angle: float
    offset: float


@dataclass
class _Scan:
    views_left: int
    seen: dict[int, Sighting] = field(default_factory=dict)


@dataclass
class WorldMap:
    """What the robot keeps of one world across episodes (``memory="world"``), in the
    map frame (the robot's own frame of the first episode): the visibility ``graph``,
    the landmarks ``explored`` (scanned from), the last known ``positions`` (m) of the
    landmarks seen and the ``standing`` pose (x, y, heading; m, rad) of each landmark
    stood at, recorded the first time (the anchors of relocalisation)."""

    graph: VisibilityGraph = field(default_factory=VisibilityGraph)
    explored: set[int] = field(default_factory=set)
    positions: dict[int, np.ndarray] = field(default_factory=dict)
    standing: dict[int, np.ndarray] = field(default_factory=dict)


@dataclass
class SelfSimilarController(Controller):
    """Briggs et al.'s explore/navigate controller; see the module docstring.

    ``planning``: ``"deterministic"`` (§4.2) or ``"probabilistic"`` (§4.3).
    ``view_hfov_deg``: horizontal field of view of the ``view`` camera (degrees, its
    calibration). ``window``, ``row_step``: detector w and k (pixels; 22 and 3 for
    320 x 240 images, the paper's 45 and 6 scaled). ``scan_step_deg``: turn between the
    views of a scan (degrees, at most the field of view). ``standoff``: distance of the
    standing place from a panel (m). ``step_length``: longest move before looking again
    (m). ``far``: beyond it (m) the approach follows the line of sight. ``look_cost``:
    cost of a scan or of staying (m). ``wander_distance``: move when no landmark is in
    sight (m). ``memory``: ``"world"`` (the paper's: the map persists across the episodes
    of one world, see the module docstring) or ``"episode"`` (each episode explores from
    scratch).
    """

    planning: str = "deterministic"
    memory: str = "world"
    view_hfov_deg: float = 60.0
    window: int = 22
    row_step: int = 3
    scan_step_deg: float = 30.0
    standoff: float = 1.0
    step_length: float = 0.5
    far: float = 2.5
    look_cost: float = 0.5
    wander_distance: float = 1.0

    moves_home: ClassVar[bool] = False
    reads_at_decisions_only: ClassVar[bool] = True
    envs: ClassVar[tuple[str, ...] | None] = ("homing_gym/LandmarkNavigation-v0",)

    def validate(self) -> None:
        if self.planning not in PLANNING:
            raise ValueError(f"selfsimilar: unknown planning {self.planning!r}; "
                             f"allowed: {PLANNING}")
        if self.memory not in MEMORY:
            raise ValueError(f"selfsimilar: unknown memory {self.memory!r}; "
                             f"allowed: {MEMORY}")
        for name in ("view_hfov_deg", "standoff", "step_length", "far", "look_cost",
                     "wander_distance"):
            value = getattr(self, name)
            require_positive(f"selfsimilar: {name}", value)
        if not self.view_hfov_deg < 180:
            raise ValueError(f"selfsimilar: view_hfov_deg must be below 180 degrees, "
                             f"got {self.view_hfov_deg!r}")
        if not 0 < self.scan_step_deg <= self.view_hfov_deg:
            raise ValueError(f"selfsimilar: scan_step_deg must be in (0, view_hfov_deg = "
                             f"{self.view_hfov_deg}] degrees so that views overlap, "
                             f"got {self.scan_step_deg!r}")
        self._detector = DetectorConfig(window=self.window, row_step=self.row_step)

    def __post_init__(self) -> None:
        super().__post_init__()
        self._maps: dict[str, WorldMap] = {}     # memory="world": one map per world
        self._world = ""
        self.on_reset()

    def observation_keys(self) -> tuple[str, ...]:
        return ("view", "goal_id", "odometry")

    def keeps_memory_across_episodes(self) -> bool:
        return self.memory == "world"

    def check_env(self, env) -> None:
        """Note which world the episodes are in: the env's scene, by name (what an
        operator tells the robot, "you are in building X"; nothing of its layout, its
        landmark changes or the robot's pose is read). A procedural scene draws another
        world under the same name, so ``memory="world"`` refuses it (``ValueError``)."""
        if self.memory == "world" and env.unwrapped.draws_worlds:
            raise ValueError(f"selfsimilar: memory='world' keeps one map per scene name, "
                             f"but scene {env.unwrapped.scene.name!r} draws a new world "
                             f"each episode; use memory='episode'")
        self._world = str(env.unwrapped.scene.name)

    # -- memory -----------------------------------------------------------------------------
    def on_reset(self) -> None:
        """A new episode: the world's map is kept (``memory="world"``) or started afresh;
        everything else is per episode. With a map that has anchors, the robot is not
        localised until it stands at one of them (:meth:`_relocalise`)."""
        if self.memory == "episode":
            self._map = WorldMap()
        else:
            self._map = self._maps.setdefault(self._world, WorldMap())
        #: The map memory: the visibility graph, the landmarks scanned from, and the
        #: landmark the robot stands at (``None`` between landmarks).
        self.graph = self._map.graph
        self.explored = self._map.explored
        self._localised = not self._map.standing  # no anchor: this episode's frame ...
        if self._localised:                       # ... and nothing ties the last one to it
            self._map.positions.clear()
        self._unmapped: list[tuple] = []         # graph updates held until localised
        self._pose = np.zeros(3)                 # dead-reckoned (x, y, heading), own frame
        self._odometry: np.ndarray | None = None
        self._rng = np.random.default_rng(self._seed)
        self.at: int | None = None
        self._came_from: int | None = None
        self._travelled = 0.0
        self._scan: _Scan | None = None
        self._scans_here = 0
        self._now: dict[int, Detection] = {}     # detections in the current view
        self._misses = 0
        self._look: int | None = None
        self._target: int | None = None
        self._centre: np.ndarray | None = None   # target panel centre, own frame (m)
        self._normal: float | None = None        # its normal, own frame (rad)
        self._refines = 0
        #: Position (m) of every landmark seen, for dead reckoning (§4.2): the map's, in
        #: the map frame, once localised; until then this episode's, in its own frame.
        self.positions: dict[int, np.ndarray] = self._map.positions if self._localised else {}
        self._reckoning = False                  # servoing towards a remembered position
        self._lost: set[int] = set()             # not found where dead reckoning put them
        self._before_drive: np.ndarray | None = None  # the view when the last drive began
        self._blocks = 0
        self._escape: list[Move] = []            # queued moves out of a blocked drive
        self._pending: Move | None = None        # the drive after a split-off turn

    # -- decisions --------------------------------------------------------------------------
    def decide(self, observation: dict[str, np.ndarray]) -> Move | None:
        missing = [k for k in self.observation_keys() if k not in observation]
        if missing:
            raise ValueError(f"selfsimilar needs the observation keys {missing} "
                             f"(obs_keys must include {list(self.observation_keys())})")
        self._dead_reckon(np.asarray(observation["odometry"], dtype=np.float64))
        goal = int(np.argmax(observation["goal_id"]))
        gray = to_gray(observation["view"])
        model = PerspectiveModel.from_fov(gray.shape[1], gray.shape[0],
                                          math.radians(self.view_hfov_deg))
        self._now = {d.id: d for d in detect_landmarks(gray, model, self._detector)}
        move = self._choose(gray, model, goal)
        if move is not None and move.distance > 0 and abs(move.direction) > SPLIT_TURN:
            self._pending = Move(0.0, move.distance)
            move = Move(move.direction, 0.0)
        self._before_drive = gray if move is not None and move.distance > 0 else None
        return move

    def _choose(self, gray, model, goal: int) -> Move | None:
        if self._pending is not None:        # after a turn: nothing to check yet
            move, self._pending = self._pending, None
            return move
        if self._escape:
            return self._escape.pop(0)
        if self._blocked(gray):
            self._blocks += 1
            if self._blocks <= MAX_BLOCKS:
                side = math.pi / 2 if self._blocks % 2 else -math.pi / 2
                self._escape = [Move(side, SIDESTEP)]
                return Move(math.pi, SIDESTEP)
            self._blocks = 0
            return self._start_scan(goal)
        if self._scan is not None:
            return self._scanning(goal)
        if self._look is not None:
            return self._looking(gray, model, goal)
        if self._target is None and self.at == goal:
            if self._refines >= MAX_REFINES:
                return None
            self._refines += 1
            self._target, self._came_from = goal, None
        if self._target is not None:
            return self._servo(gray, model, goal)
        return self._start_scan(goal)

    def _dead_reckon(self, odometry: np.ndarray) -> None:
        """Move the own pose by the odometry increment since the last decision."""
        if self._odometry is not None:
            c, s = math.cos(self._odometry[2]), math.sin(self._odometry[2])
            dx, dy = odometry[:2] - self._odometry[:2]
            forward, left = c * dx + s * dy, -s * dx + c * dy
            h = self._pose[2]
            self._pose[0] += math.cos(h) * forward - math.sin(h) * left
            self._pose[1] += math.sin(h) * forward + math.cos(h) * left
            self._pose[2] = wrap_angle(h + odometry[2] - self._odometry[2])
            self._travelled += math.hypot(dx, dy)
        self._odometry = odometry.copy()

    def _blocked(self, gray: np.ndarray) -> bool:
        """Whether the last drive left the view ``gray`` (nearly) as it was (see
        ``BLOCKED_CHANGE``); a drive that changed it ends a run of blocked ones."""
        if self._before_drive is None:
            return False
        if float(np.mean(np.abs(gray - self._before_drive))) >= BLOCKED_CHANGE:
            self._blocks = 0
            return False
        return True

    def _to_robot(self, point: np.ndarray) -> np.ndarray:
        d = point - self._pose[:2]
        c, s = math.cos(self._pose[2]), math.sin(self._pose[2])
        return np.array([c * d[0] + s * d[1], -s * d[0] + c * d[1]])

    def _to_own(self, point) -> np.ndarray:
        c, s = math.cos(self._pose[2]), math.sin(self._pose[2])
        return self._pose[:2] + np.array([c * point[0] - s * point[1],
                                          s * point[0] + c * point[1]])

    # -- scanning (§4.1) --------------------------------------------------------------------
    def _start_scan(self, goal: int) -> Move | None:
        """Scan, starting with the current view."""
        self._scan = _Scan(views_left=math.ceil(360.0 / self.scan_step_deg - 1e-9))
        self._scans_here += 1
        return self._scanning(goal)

    def _scanning(self, goal: int) -> Move | None:
        scan = self._scan
        for landmark, det in self._now.items():
            old = scan.seen.get(landmark)
            if old is None or abs(det.bearing) < old.offset:
                angle = wrap_angle(self._pose[2] + det.bearing)
                scan.seen[landmark] = Sighting(det.distance, angle, abs(det.bearing))
                self.positions[landmark] = self._pose[:2] + det.distance * np.array(
                    [math.cos(angle), math.sin(angle)])
        scan.views_left -= 1
        if scan.views_left > 0:
            return Move(math.radians(self.scan_step_deg), 0.0)
        self._scan = None
        if self._target is not None:          # a search for the servo target
            if self._target in scan.seen:
                return self._head_for(self._target, scan.seen[self._target])
            if self._reckoning:
                self._lost.add(self._target)
            self._target = self._came_from = None
            self.at = None
        if self.at is None:
            return self._leave_nowhere(scan.seen, goal)
        if not self._localised:               # at a landmark the map has no anchor for
            self._unmapped.append(("observe", self.at, {
                b: (s.distance, s.angle) for b, s in scan.seen.items()}))
            return self._leave_nowhere(scan.seen, goal)
        self._recalibrate(scan.seen)
        self.graph.observe(self.at, {b: (s.distance, s.angle) for b, s in scan.seen.items()})
        self.explored.add(self.at)
        return self._plan(goal, set(scan.seen))

    def _recalibrate(self, seen: dict[int, Sighting]) -> None:
        """Correct the heading from landmarks seen before from here (§4.1)."""
        diffs = [wrap_angle(info.angle - s.angle) for b, s in seen.items()
                 for info in (self.graph.edge(self.at, b),) if info is not None and info.seen]
        if not diffs:
            return
        shift = math.atan2(np.mean(np.sin(diffs)), np.mean(np.cos(diffs)))
        if abs(shift) <= MAX_RECALIBRATION:
            self._pose[2] = wrap_angle(self._pose[2] + shift)
            for s in seen.values():
                s.angle = wrap_angle(s.angle + shift)

    def _leave_nowhere(self, seen: dict[int, Sighting], goal: int) -> Move:
        """Away from landmarks, or at one the map has no anchor for while not localised:
        to the goal if seen, else the nearest one (§4.2): an anchor of the map if any is
        seen and the robot is not localised, else one not scanned from yet if any is
        seen; with nothing seen dead reckoning or wander."""
        seen = {b: s for b, s in seen.items() if b != self.at}
        if not seen:
            return self._reckon_or_wander(goal)
        anchors = [] if self._localised else [b for b in seen if b in self._map.standing]
        options = anchors or [b for b in seen if b not in self._scanned()] or list(seen)
        target = goal if goal in seen else min(options, key=lambda b: seen[b].distance)
        self._came_from = self.at
        return self._head_for(target, seen[target])

    # -- planning at a landmark (§4.1-4.3) ---------------------------------------------------
    def _plan(self, goal: int, visible: set[int] | None) -> Move | None:
        """At landmark ``self.at``: the next move. ``visible``: the landmarks of a full
        scan just made, ``None`` when there was none."""
        here = self.at
        if self.planning == "probabilistic" and goal in self.graph.graph:
            values = self.graph.expected_lengths(goal, self.look_cost)
            if math.isfinite(values.get(here, math.inf)):
                nxt = here if visible is None else self.graph.best_next(
                    here, visible, values, self.look_cost)
                return self._scan_again(goal) if nxt == here else self._look_for(nxt)
        elif self.planning == "deterministic":
            path = self.graph.shortest_path(here, goal)
            if path is not None:
                return self._look_for(path[1])
        reaching = self._reaching(goal) - {here}
        if reaching:
            return self._reckon_to(reaching)
        hop = self._exploration_hop(here)
        if hop is not None:
            return self._look_for(hop)
        return self._scan_again(goal)

    def _reaching(self, goal: int) -> set[int]:
        """Landmarks with a known position, not lost, from which the goal is reachable
        (deterministic: over edges believed visible; probabilistic: finite expected
        length)."""
        if self.planning == "probabilistic":
            values = (self.graph.expected_lengths(goal, self.look_cost)
                      if goal in self.graph.graph else {})
            found = {x for x, v in values.items() if math.isfinite(v)}
        else:
            found = self.graph.reaching(goal)
        if goal in self.positions:
            found.add(goal)
        return {x for x in found if x in self.positions and x not in self._lost}

    def _reckon_or_wander(self, goal: int) -> Move:
        """No landmark to servo to: dead reckoning (§4.2) to the closest landmark from
        which the goal is reachable, else to the closest one not scanned from; else
        wander."""
        here = {self.at} if self.at is not None else set()
        for options in (self._reaching(goal) - here,
                        set(self.positions) - self._scanned() - self._lost - here):
            if options:
                return self._reckon_to(options)
        return self._wander()

    def _reckon_to(self, options: set[int]) -> Move:
        """Drive towards the closest of ``options`` by its remembered position."""
        target = min(options, key=lambda b: float(np.hypot(*(self.positions[b]
                                                             - self._pose[:2]))))
        self._target, self._centre, self._normal = target, self.positions[target].copy(), None
        self.at, self._came_from, self._reckoning = None, None, True
        self._travelled, self._scans_here, self._misses = 0.0, 0, 0
        centre = self._to_robot(self._centre)
        return Move(math.atan2(centre[1], centre[0]), 0.0)

    def _scan_again(self, goal: int) -> Move:
        """Stay and scan again (§4.3), unless this landmark was scanned from
        ``MAX_SCANS_HERE`` times since the robot came: then dead reckoning or wander."""
        if self._scans_here < MAX_SCANS_HERE:
            return self._start_scan(goal)
        return self._reckon_or_wander(goal)

    def _scanned(self) -> set[int]:
        """The landmarks scanned from: the map's, and this episode's held back."""
        return self.explored | {op[1] for op in self._unmapped if op[0] == "observe"}

    def _wander(self) -> Move:
        """Nothing to go to: ``wander_distance`` in a random direction."""
        self.at, self._scans_here = None, 0
        return Move(float(self._rng.uniform(-math.pi, math.pi)), self.wander_distance)

    def _exploration_hop(self, here: int) -> int | None:
        """First landmark on the way to the closest landmark not scanned from yet, by
        edge lengths plus ``look_cost`` per landmark (§4.1)."""
        usable = nx.subgraph_view(
            self.graph.graph, filter_edge=lambda a, b: self.graph.edge(a, b).visible)
        costs, paths = nx.single_source_dijkstra(
            usable, here, weight=lambda a, b, d: d["info"].length + self.look_cost)
        todo = [b for b in costs if b not in self.explored]
        if not todo:
            return None
        return paths[min(todo, key=costs.get)][1]

    def _look_for(self, landmark: int) -> Move:
        """Turn to where ``landmark`` is expected from here; the next view tells."""
        self._look = landmark
        return Move(wrap_angle(self.graph.edge(self.at, landmark).angle - self._pose[2]), 0.0)

    def _looking(self, gray, model, goal: int) -> Move | None:
        landmark, self._look = self._look, None
        if landmark not in self._now:              # §4.2: update the graph and replan
            self.graph.mark_invisible(self.at, landmark)
            return self._plan(goal, None)
        self._came_from, self.at, self._travelled = self.at, None, 0.0
        self._target, self._centre, self._normal = landmark, None, None
        self._scans_here = self._misses = 0
        return self._servo(gray, model, goal)

    # -- visual servoing (§4.1-4.2) ----------------------------------------------------------
    def _head_for(self, landmark: int, sighting: Sighting) -> Move:
        """Start servoing to ``landmark`` seen at ``sighting``: turn towards it."""
        self._target, self._normal, self.at = landmark, None, None
        self._travelled, self._scans_here, self._misses = 0.0, 0, 0
        self._reckoning = False
        direction = np.array([math.cos(sighting.angle), math.sin(sighting.angle)])
        self._centre = self._pose[:2] + sighting.distance * direction
        return Move(wrap_angle(sighting.angle - self._pose[2]), 0.0)

    def _servo(self, gray, model, goal: int) -> Move | None:
        det = self._now.get(self._target)
        if det is not None:
            self._misses, self._reckoning = 0, False
            self._update_target(gray, model, det)
        elif self._centre is None:
            return self._start_scan(goal)
        centre = self._to_robot(self._centre)
        distance = float(np.hypot(*centre))
        bearing = math.atan2(centre[1], centre[0])
        if self._normal is None or distance > self.far:
            aim = centre * (1 - self.standoff / max(distance, self.standoff))
        else:
            out = self._normal - self._pose[2]
            aim = centre + max(self.standoff, 0.6 * distance) * np.array(
                [math.cos(out), math.sin(out)])
        arrived = np.hypot(*aim) < ARRIVE_DISTANCE and self._normal is not None
        if abs(bearing) > ARRIVE_ANGLE and (det is None or arrived):
            return Move(bearing, 0.0)         # face it: close by it fills the view
        if arrived:                           # by the last estimate and dead reckoning
            return self._arrive(goal)
        if det is None or np.hypot(*aim) < ARRIVE_DISTANCE:  # lost, or no normal yet
            self._misses += 1
            closer = distance - self.standoff - 0.2
            if (self._misses > MAX_MISSES and not self._reckoning) or closer <= 0:
                self._misses = 0
                return self._start_scan(goal)  # not where it should be: search
            return Move(bearing, min(self.step_length, closer))  # too far to read?
        return Move(math.atan2(aim[1], aim[0]), min(self.step_length, float(np.hypot(*aim))))

    def _update_target(self, gray, model, det: Detection) -> None:
        """The target's centre and normal (own frame) from its detection ``det``; the
        normal is averaged with the previous estimate (unit vectors, equal weights)."""
        pose = panel_pose(gray, det, model, self._detector.p, self._detector.layout)
        if pose is None:
            self._centre = self._to_own(det.distance * np.array(
                [math.cos(det.bearing), math.sin(det.bearing)]))
            self.positions[self._target] = self._centre.copy()
            return
        self._centre = self._to_own(pose.centre)
        self.positions[self._target] = self._centre.copy()
        normal = pose.normal + self._pose[2]
        if self._normal is not None:
            normal = math.atan2(math.sin(normal) + math.sin(self._normal),
                                math.cos(normal) + math.cos(self._normal))
        self._normal = wrap_angle(normal)

    def _arrive(self, goal: int) -> Move | None:
        """Standing in front of the target: annotate the edge driven (§4.1), take the
        pose of the landmark's anchor (relocalising if not localised; else it clears the
        drift of dead reckoning) or record this standing pose as its anchor, then finish
        (the goal) or scan / plan the next hop."""
        landmark = self._target
        if self._came_from is not None:
            self._update_map("traversed", self._came_from, landmark, self._travelled)
        self.at, self._target, self._came_from = landmark, None, None
        self._centre = self._normal = None
        self._scans_here = 0
        self._lost.clear()
        relocalised = not self._localised and landmark in self._map.standing
        if relocalised:
            self._relocalise(landmark)
        elif self._localised and landmark in self._map.standing:
            self._pose = self._map.standing[landmark].copy()   # the drift goes
        else:
            self._update_map("stood", landmark, self._pose.copy())
        if landmark == goal:
            return None
        if (relocalised or not self._localised or self.planning == "probabilistic"
                or landmark not in self.explored):
            return self._start_scan(goal)
        return self._plan(goal, None)

    def _update_map(self, kind: str, *args) -> None:
        """A map update: ``("traversed", a, b, metres)`` or ``("stood", landmark, pose)``;
        held (with ``"observe"`` updates, see :meth:`_scanning`) while the robot is not
        localised, since its frame is not yet the map's."""
        if not self._localised:
            self._unmapped.append((kind, *args))
        elif kind == "traversed":
            self.graph.traversed(*args)
        else:
            landmark, pose = args
            self._map.standing.setdefault(landmark, pose)

    def _relocalise(self, landmark: int) -> None:
        """Standing at ``landmark``, an anchor of the map: take its recorded standing pose
        as the robot's pose (the scan that follows refines the heading, §4.1), carry this
        episode's landmark positions and held map updates into the map frame, and use
        the map's positions from now on."""
        anchor = self._map.standing[landmark]
        turn = wrap_angle(anchor[2] - self._pose[2])
        c, s = math.cos(turn), math.sin(turn)
        rotation = np.array([[c, -s], [s, c]])

        def to_map(point: np.ndarray) -> np.ndarray:
            return anchor[:2] + rotation @ (point - self._pose[:2])

        for b, point in self.positions.items():
            self._map.positions[b] = to_map(point)
        held, self._unmapped, self._localised = self._unmapped, [], True
        for kind, *args in held:
            if kind == "observe":
                at, seen = args
                self.graph.observe(at, {b: (d, wrap_angle(a + turn))
                                        for b, (d, a) in seen.items()})
                self.explored.add(at)
            elif kind == "stood":
                b, pose = args
                self._update_map("stood", b, np.array([*to_map(pose[:2]),
                                                       wrap_angle(pose[2] + turn)]))
            else:
                self._update_map(kind, *args)
        self._pose = anchor.copy()
        self.positions = self._map.positions
