"""The evaluation harness: one loop that scores every method on identical episodes.

Episode ``i`` of a suite with seed ``S`` is ``env.reset(seed=S + i)``, so every method sees
the same scenes, homes and starts. Policies see only the observation; the harness alone
reads ``info`` and the env's ground truth to compute the metrics of :mod:`homing_train.harness.metrics`.

The ``homing-eval`` command is :mod:`homing_train.harness.eval_command`.
"""

from __future__ import annotations

import argparse
import contextlib
import csv
import dataclasses
import inspect
import json
import math
import os
import socket
import time
from dataclasses import asdict, dataclass, field
from typing import Any, Callable, Sequence

import gymnasium as gym
import numpy as np
from tqdm import tqdm

import homing_gym
from homing_gym.cli import add_env_arguments, seed_value, worker_count
from homing_gym.validation import is_real, require_number, require_positive
from homing_gym.env import HomingEnv, simulation_settings
from homing_gym.paths import NoPathError, path_length, shortest_path
from homing_gym.geometry import wrap_angle
from homing_train import DEFAULT_ENV
from homing_train.extras import require_extra
from homing_train.harness import metrics
from homing_train.harness.policies import (PolicySpec, parse_params, policy_spec,
                                           recorded_settings)
from homing_train.harness.rollout import prepare_policy, rollout
from homing_gym.outputs import OutputLock, atomic_path, write_text_atomic
from homing_train.pool import pool_results, stop_on_signals

SCHEMA = 1


@dataclass
class EpisodeRecord:
    """Outcome of one episode (metres, radians unless named otherwise)."""

    seed: int
    start_pose: list[float]
    home_pose: list[float]
    start_distance: float
    shortest_path: float
    success: bool
    terminated: bool
    truncated: bool
    steps: int
    path_length: float
    final_distance: float
    min_distance: float
    collisions: int
    spl: float
    soft_spl: float
    final_heading_error_deg: float
    wall_time: float
    trajectory: list[list[float]] = field(default_factory=list, repr=False)
    # on a route (None elsewhere; metrics.targets_reached_in_order)
    targets: int | None = None                   # targets on the route
    target_errors: list[float] | None = None     # the env's: distance each was left at (m)
    targets_finished: int | None = None          # targets left (len(target_errors))
    targets_reached: int | None = None           # reached in order, within the radius
    all_targets_within_radius: bool | None = None  # every target left within the radius

    @property
    def reached(self) -> bool | None:
        """On a route, whether every target was reached in order; elsewhere ``None``
        (:func:`summarize` then uses ``min_distance``)."""
        return None if self.targets is None else self.targets_reached == self.targets

    @classmethod
    def from_doc(cls, doc: Any) -> "EpisodeRecord":
        """The record of a JSON object (a stream line, an episode of a result JSON);
        ``ValueError`` naming the first field that is missing, of the wrong type or
        impossible (:data:`RECORD_RANGES`: NaN, a negative count or length, an SPL above
        1, ...). Keys it does not know are ignored."""
        if not isinstance(doc, dict):
            raise ValueError(f"an episode record is a JSON object, got {doc!r:.80}")
        fields = dataclasses.fields(cls)
        missing = [f.name for f in fields if f.name not in doc
                   and f.default is dataclasses.MISSING
                   and f.default_factory is dataclasses.MISSING]
        if missing:
            raise ValueError(f"episode record lacks the fields {missing}")
        values = {f.name: doc[f.name] for f in fields if f.name in doc}
        for name, (low, high, integer) in RECORD_RANGES.items():
            if name not in ROUTE_FIELDS or values.get(name) is not None:
                values[name] = require_number(name, values.get(name), low, high,
                                              integer=integer)
        for name in ("success", "terminated", "truncated", "all_targets_within_radius"):
            value = values.get(name)
            if not (isinstance(value, bool) or (value is None and name in ROUTE_FIELDS)):
                raise ValueError(f"{name} must be true or false, got {value!r:.80}")
        for name, size in (("start_pose", 3), ("home_pose", 3), ("trajectory", None),
                           ("target_errors", None)):
            if values.get(name) is not None:
                _check_numbers(name, values[name], size)
        return cls(**values)


#: :class:`EpisodeRecord`'s fields that are ``None`` off a route.
ROUTE_FIELDS = ("targets", "target_errors", "targets_finished", "targets_reached",
                "all_targets_within_radius")
_COUNT = 2**63 - 1           # the largest count or seed a record may hold
#: Ranges of :class:`EpisodeRecord`'s numbers: (low, high, integer).
RECORD_RANGES: dict[str, tuple[float, float, bool]] = {
    "seed": (0, _COUNT, True), "start_distance": (0, math.inf, False),
    "shortest_path": (0, math.inf, False), "steps": (0, _COUNT, True),
    "path_length": (0, math.inf, False), "final_distance": (0, math.inf, False),
    "min_distance": (0, math.inf, False), "collisions": (0, _COUNT, True),
    "spl": (0, 1, False), "soft_spl": (0, 1, False),
    "final_heading_error_deg": (0, 180, False), "wall_time": (0, math.inf, False),
    "targets": (0, _COUNT, True), "targets_finished": (0, _COUNT, True),
    "targets_reached": (0, _COUNT, True)}


def _check_numbers(name: str, value: Any, size: int | None) -> None:
    """``ValueError`` unless ``value`` is a list of ``size`` finite numbers (``size``
    ``None``: any number of them, or of lists of two: a trajectory's points; the
    errors at targets must be >= 0)."""
    if not isinstance(value, list) or (size is not None and len(value) != size):
        raise ValueError(f"{name} must be a list of {size or 'any number of'} numbers, "
                         f"got {value!r:.80}")
    points = value if name == "trajectory" else [value]
    for point in points:
        if not (isinstance(point, list) and (name != "trajectory" or len(point) == 2)
                and all(is_real(v) for v in point)) or (
                name == "target_errors" and any(v < 0 for v in point)):
            raise ValueError(f"{name} holds a value that is not a finite number"
                             f"{' pair' if name == 'trajectory' else ''}"
                             f"{' >= 0' if name == 'target_errors' else ''}: {point!r:.80}")


@dataclass
class EvalResult:
    """A suite's episodes and summary; ``to_dict`` gives the JSON document (schema 1)."""

    policy: str
    params: dict[str, Any]
    env_id: str
    env_kwargs: dict[str, Any]
    seed: int
    episodes: list[EpisodeRecord]
    bin_width: float = 0.3
    summary: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        if not self.summary:
            self.summary = summarize(self.episodes, self.bin_width, seed=self.seed,
                                     radius=self.success_radius)

    @property
    def success_radius(self) -> float:
        """The episodes' success radius (metres): the env's ``success_radius``, else the
        tasks' default 0.15."""
        return float(self.env_kwargs.get("success_radius", 0.15))

    @property
    def success_on(self) -> str | None:
        """The success rule the episodes were scored under (``"stop"`` or ``"reach"``, as
        recorded in the env kwargs; ``None`` for a result that did not record it)."""
        return self.env_kwargs.get("success_on")

    def to_dict(self) -> dict[str, Any]:
        return {"schema": SCHEMA, "policy": self.policy, "params": self.params,
                "env_id": self.env_id, "success_on": self.success_on,
                "env_kwargs": self.env_kwargs, "seed": self.seed,
                "homing_gym_version": homing_gym.__version__, "summary": self.summary,
                "episodes": [asdict(e) for e in self.episodes]}

    def save(self, path: str) -> None:
        """Write the JSON document to ``path`` and the episode table to ``path`` .csv,
        each atomically (an interrupted save leaves the old file or the new one)."""
        write_text_atomic(path, json.dumps(self.to_dict(), default=_json_default))
        write_csv(self.episodes, os.path.splitext(path)[0] + ".csv", self.success_on)

    @classmethod
    def load(cls, path: str) -> "EvalResult":
        """Read a result JSON; ``ValueError`` naming the file if it is not schema 1."""
        try:
            with open(path) as f:
                doc = json.load(f)
        except (OSError, json.JSONDecodeError, UnicodeDecodeError) as err:
            raise ValueError(f"{path}: not a readable result JSON ({err})") from None
        if isinstance(doc, dict) and "protocol" in doc and "settings" in doc:
            folder = (os.path.dirname(path) if os.path.basename(path) == "cell.json"
                      else os.path.splitext(path)[0])
            raise ValueError(f"{path}: a protocol cell (homing-eval --protocol), not an "
                             f"episode result; compare its settings' results, the other "
                             f".json files in {folder}/")
        if not isinstance(doc, dict) or doc.get("schema") != SCHEMA:
            raise ValueError(f"{path}: expected a homing-eval result with schema {SCHEMA}, "
                             f"got schema {doc.get('schema') if isinstance(doc, dict) else None!r}")
        missing = [k for k in ("policy", "env_id", "seed", "summary", "episodes") if k not in doc]
        if missing:
            raise ValueError(f"{path}: result JSON lacks {missing}")
        if not isinstance(doc["episodes"], list) or not doc["episodes"]:
            raise ValueError(f"{path}: the result holds no episodes (episodes: "
                             f"{doc['episodes']!r:.40}), so it has nothing to report")
        episodes = []
        for i, e in enumerate(doc["episodes"]):
            try:
                episodes.append(EpisodeRecord.from_doc(e))
            except ValueError as err:
                raise ValueError(f"{path}: episode {i}: {err}") from None
        summary = doc["summary"]
        if not isinstance(summary, dict) or summary.get("episodes") != len(episodes):
            raise ValueError(f"{path}: its summary (of "
                             f"{summary.get('episodes') if isinstance(summary, dict) else None}"
                             f" episodes) is not of its {len(episodes)} episodes: the file "
                             f"was edited or mixed; rerun homing-eval")
        return cls(policy=doc["policy"], params=doc.get("params", {}), env_id=doc["env_id"],
                   env_kwargs=doc.get("env_kwargs", {}), seed=doc["seed"], episodes=episodes,
                   summary=doc["summary"])


def _json_default(obj: Any) -> Any:
    if isinstance(obj, np.generic):
        return obj.item()
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    return repr(obj)


def write_csv(episodes: Sequence[EpisodeRecord], path: str, success_on: str | None) -> None:
    """One row per episode, every field but the trajectory, and the success rule
    ``success_on`` the episodes were scored under (empty when unrecorded)."""
    names = [f.name for f in dataclasses.fields(EpisodeRecord) if f.name != "trajectory"]
    with atomic_path(path) as tmp, open(tmp, "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=[*names, "success_on"])
        writer.writeheader()
        for e in episodes:
            row = asdict(e)
            writer.writerow({**{k: (json.dumps(row[k]) if isinstance(row[k], list) else row[k])
                                for k in names}, "success_on": success_on or ""})


def summarize(episodes: Sequence[EpisodeRecord], bin_width: float = 0.3,
              seed: int = 0, radius: float = 0.15) -> dict[str, Any]:
    """Means with 95% CIs (success: Wilson; the others: seeded percentile bootstrap of the
    mean), success by start-distance bin, and ``reached_rate``: the share of episodes
    that came within ``radius`` metres of the goal at any time (stopped there or not); on
    a route, that reached every target in order (:attr:`EpisodeRecord.reached`), and the
    route's own means (:func:`route_summary`)."""
    if not episodes:
        raise ValueError("no episodes to summarize")

    def col(name: str) -> np.ndarray:
        return np.array([getattr(e, name) for e in episodes], dtype=np.float64)

    out: dict[str, Any] = {"episodes": len(episodes)}
    for key, name in (("success_rate", "success"), ("spl", "spl"), ("soft_spl", "soft_spl"),
                      ("final_distance_mean", "final_distance"),
                      ("path_length_mean", "path_length"), ("steps_mean", "steps"),
                      ("collisions_mean", "collisions"), ("min_distance_mean", "min_distance"),
                      ("heading_error_deg_mean", "final_heading_error_deg")):
        values = col(name)
        out[key] = float(values.mean())
        ci_key = "success_ci" if key == "success_rate" else key.removesuffix("_mean") + "_ci"
        out[ci_key] = list(metrics.wilson_interval(int(values.sum()), values.size)
                           if key == "success_rate" else metrics.bootstrap_ci(values, seed=seed))
    reached = sum(e.min_distance <= radius if e.reached is None else e.reached
                  for e in episodes)
    out["reached_rate"] = reached / len(episodes)
    out["reached_ci"] = list(metrics.wilson_interval(reached, len(episodes)))
    final_cm = 100 * col("final_distance")
    out["final_distance_cm_median"] = float(np.median(final_cm))
    out["heading_error_deg_median"] = float(np.median(col("final_heading_error_deg")))
    out["collision_free_rate"] = float(np.mean(col("collisions") == 0))
    out["wall_time_mean"] = float(col("wall_time").mean())
    out["bin_width"] = bin_width
    out["success_by_distance"] = [asdict(b) for b in metrics.distance_bins(
        col("start_distance"), col("success"), bin_width)]
    return out | route_summary(episodes, seed)


def route_summary(episodes: Sequence[EpisodeRecord], seed: int = 0) -> dict[str, Any]:
    """Over the route episodes among ``episodes`` (none: ``{}``): ``targets_reached_fraction``
    (mean share of each route's targets reached in order, bootstrap CI),
    ``all_targets_within_radius_rate`` (Wilson CI), ``targets_finished_mean`` and the
    mean and median error (m, cm) over every target left, ``None`` if none was."""
    routes = [e for e in episodes if e.targets is not None]
    if not routes:
        return {}
    fraction = np.array([e.targets_reached / e.targets for e in routes])
    within = sum(bool(e.all_targets_within_radius) for e in routes)
    errors = np.array([x for e in routes for x in e.target_errors])
    return {"route_episodes": len(routes),
            "targets_reached_fraction": float(fraction.mean()),
            "targets_reached_fraction_ci": list(metrics.bootstrap_ci(fraction, seed=seed)),
            "all_targets_within_radius_rate": within / len(routes),
            "all_targets_within_radius_ci": list(metrics.wilson_interval(within, len(routes))),
            "targets_finished_mean": float(np.mean([e.targets_finished for e in routes])),
            "target_error_mean": float(errors.mean()) if errors.size else None,
            "target_error_cm_median": float(100 * np.median(errors)) if errors.size else None}


# -- running episodes ---------------------------------------------------------------------
def _shortest(scene, stops, radius: float, seed: int) -> float:
    """Length (m) of the shortest path through ``stops`` in order for a disc of ``radius``
    metres: the paths the oracle plans (:func:`homing_gym.paths.shortest_path`).
    ``ValueError`` where a leg has none, which no episode the env draws lacks."""
    try:
        return sum(path_length(shortest_path(scene, a, b, radius))
                   for a, b in zip(stops[:-1], stops[1:]))
    except NoPathError as err:
        raise ValueError(f"episode of seed {seed}: SPL is undefined, no path joins its start "
                         f"and goals ({err}); the env draws only joined ones, so a start or "
                         f"home given as a reset option lies out of reach") from err


def _remaining(scene, final, home, radius: float) -> float:
    """Shortest-path distance (m) from where the robot ended to home, for soft-SPL;
    infinite (soft-SPL 0) where no path leads home from there."""
    try:
        return path_length(shortest_path(scene, final, home, radius))
    except NoPathError:
        return math.inf


def run_episode(env: gym.Env, policy, seed: int, start: Sequence[float] | None = None,
                home: Sequence[float] | None = None) -> EpisodeRecord:
    """Run one episode of ``policy`` (which receives the observation only) and measure it
    from ``info``. ``start`` and ``home`` override the start and home poses (x, y, yaw):
    the homing field sets the start, a fixed-nest evaluation (Yu & Kim Fig. 6) both."""
    t0 = time.perf_counter()
    options = {key: [float(v) for v in pose] for key, pose in (("start", start), ("home", home))
               if pose is not None}
    run = rollout(env, policy, seed, options)
    home = np.asarray(run.reset_info["home_pose"], dtype=np.float64)
    start_pose = np.asarray(run.reset_info["start_pose"], dtype=np.float64)
    # the scene, the task's path radius and the episode's goals are public attributes,
    # read for path-length metrics: the shortest path visits every goal of a route in order
    unwrapped = env.unwrapped
    scene, radius = unwrapped.scene, unwrapped.task.path_radius
    traj = run.poses[:, :2]
    final = run.poses[-1]
    shortest = _shortest(scene, [start_pose, *unwrapped.episode.goals], radius, seed)
    final_geodesic = _remaining(scene, final, home, radius)
    p = path_length(traj)
    success = bool(run.info.get("is_success", False))
    route = _route_fields(run.info, run.poses[:, :2], unwrapped)
    return EpisodeRecord(
        seed=int(seed), start_pose=[round(float(v), 4) for v in start_pose],
        home_pose=[round(float(v), 4) for v in home],
        start_distance=float(math.dist(start_pose[:2], home[:2])),
        shortest_path=shortest, success=success, terminated=run.terminated,
        truncated=run.truncated, steps=run.steps, path_length=p,
        final_distance=float(math.dist(final[:2], home[:2])),
        min_distance=float(np.min(np.hypot(traj[:, 0] - home[0], traj[:, 1] - home[1]))),
        collisions=int(run.info.get("collisions", 0)), spl=metrics.spl(success, shortest, p),
        soft_spl=metrics.soft_spl(final_geodesic, shortest, p),
        final_heading_error_deg=abs(math.degrees(wrap_angle(final[2] - home[2]))),
        wall_time=time.perf_counter() - t0,
        trajectory=np.round(traj, 3).tolist(), **route)


def _route_fields(info: dict, positions: np.ndarray, unwrapped) -> dict[str, Any]:
    """The route fields of :class:`EpisodeRecord` from a route env's last ``info`` (its
    ``target_errors``), the recorded positions, and the episode's goals and success
    radius (public attributes); none for an env that reports no ``target_errors``."""
    if "target_errors" not in info:
        return {}
    goals, radius = unwrapped.episode.goals, unwrapped.task.success_radius
    errors = [float(e) for e in info["target_errors"]]
    return {"targets": len(goals), "target_errors": errors, "targets_finished": len(errors),
            "targets_reached": metrics.targets_reached_in_order(
                positions, [g[:2] for g in goals], radius),
            "all_targets_within_radius": len(errors) == len(goals)
            and all(e < radius for e in errors)}


_WORKER: dict[str, Any] = {}


def _init_worker(spec: PolicySpec, env_id: str, env_kwargs: dict[str, Any]) -> None:
    """Make the worker's env and policy. A failure is kept and raised by the first task
    (as the task's error: a Ray actor whose constructor raises would be retried)."""
    try:
        env = gym.make(env_id, **env_kwargs)
        _WORKER["env"] = env
        policy = spec.build()
        prepare_policy(policy, env)
        _WORKER["policy"] = policy
    except Exception as err:  # noqa: BLE001  (any failure: reported once, by the task)
        _WORKER["error"] = err


def _work(task: tuple) -> EpisodeRecord:
    if "error" in _WORKER:
        raise _WORKER["error"]
    return run_episode(_WORKER["env"], _WORKER["policy"], *task)


class _EpisodeActor:
    """A Ray actor holding one env and policy (``backend="ray"``)."""

    def __init__(self, spec: PolicySpec, env_id: str, env_kwargs: dict[str, Any]):
        _init_worker(spec, env_id, env_kwargs)

    def run(self, item: tuple[int, tuple]) -> tuple[int, EpisodeRecord]:
        return _indexed_work(item)


#: An HTTP/2 client's first bytes: the preface and an empty SETTINGS frame (RFC 9113 §3.4).
_HTTP2_HELLO = b"PRI * HTTP/2.0\r\n\r\nSM\r\n\r\n" + bytes([0, 0, 0, 4, 0, 0, 0, 0, 0])


def check_ray_address(address: str | None, timeout: float = 5.0) -> None:
    """``ValueError`` if ``address`` names a host and port (``HOST:PORT`` or
    ``ray://HOST:PORT``) where nothing accepts a connection within ``timeout`` seconds,
    or where what accepts it does not answer as Ray does (gRPC: an HTTP/2 SETTINGS
    frame) within ``timeout`` seconds more: Ray itself keeps retrying such an address
    for minutes."""
    if not address or address == "auto":
        return
    host, _, port = address.removeprefix("ray://").rpartition(":")
    if not host or not port.isdigit():
        raise ValueError(f"ray address {address!r}: expected HOST:PORT, ray://HOST:PORT or 'auto'")
    try:
        connection = socket.create_connection((host, int(port)), timeout=timeout)
    except OSError as err:
        raise ValueError(f"ray address {address!r}: nothing answers there ({err}); 'auto' "
                         f"joins a cluster running on this machine") from None
    with connection:
        try:
            connection.sendall(_HTTP2_HELLO)
            answer = connection.recv(9)
        except OSError:                          # socket.timeout included
            answer = b""
    if len(answer) < 4 or answer[3] != 4:        # the frame's type: 4 is SETTINGS
        said = f"it said {answer[:40]!r}" if answer else "it said nothing"
        raise ValueError(f"ray address {address!r}: something answers there, but not as "
                         f"Ray does (no gRPC handshake in {timeout:g} s: {said}); give the "
                         f"head node's GCS address (HOST:6379) or its Ray Client address "
                         f"(ray://HOST:10001)")


def _ray_records(spec: PolicySpec, env_id: str, env_kwargs: dict[str, Any],
                 tasks: Sequence[tuple], workers: int, address: str | None):
    """``(index, record)`` of every task as Ray actors finish them: ``workers`` actors on
    the cluster at ``address`` (``"auto"``: the running one), or on a local Ray started
    with ``workers`` CPUs. A worker's error is raised as itself."""
    require_extra("ray", "backend='ray'")
    import ray
    from ray.util import ActorPool

    if not ray.is_initialized():
        check_ray_address(address)
        user_modules = {k: v for k, v in os.environ.items() if k == "HOMING_GYM_IMPORT"}
        local = {} if address else {"num_cpus": workers, "object_store_memory": 200 * 2**20,
                                    "include_dashboard": False}
        try:
            ray.init(address=address or "local",   # never a cluster found by chance
                     log_to_driver=False, logging_level="ERROR",
                     runtime_env={"env_vars": user_modules} if user_modules else None,
                     **local)
        except ConnectionError as err:          # e.g. 'auto' with no cluster running here
            found = ("no Ray cluster runs on this machine" if address == "auto"
                     else f"cannot join it ({err})")
            raise ValueError(f"ray address {address!r}: {found}; start one with 'ray start "
                             f"--head', or leave out --ray-address for a local Ray") from None
    actor = ray.remote(num_cpus=1)(_EpisodeActor)
    pool = ActorPool([actor.remote(spec, env_id, env_kwargs)
                      for _ in range(min(workers, len(tasks)))])
    try:
        yield from pool.map_unordered(lambda a, item: a.run.remote(item),
                                      list(enumerate(tasks)))
    except ray.exceptions.RayTaskError as err:
        raise err.cause from None


BACKENDS = ("local", "ray")


@stop_on_signals()
def run_episodes(spec: PolicySpec, env_id: str, env_kwargs: dict[str, Any],
                 tasks: Sequence[tuple], workers: int = 1,
                 progress: bool = True, desc: str = "episodes",
                 on_record: Callable[[EpisodeRecord], None] | None = None,
                 backend: str = "local", address: str | None = None
                 ) -> list[EpisodeRecord]:
    """Run ``tasks`` = [(seed, start pose or None[, home pose or None]), ...] over
    ``workers`` processes (``backend="local"``: spawned processes, 1 = in this process;
    ``"ray"``: Ray actors, on the cluster at ``address`` or a local Ray). Records come
    back in task order, the same on either backend; ``on_record`` sees each one as soon
    as it is finished (in finishing order). A policy whose episodes depend on the ones
    before (:attr:`PolicySpec.sequential`) runs them in order in this process, whatever
    ``workers`` and ``backend`` say, so results do not depend on how episodes are split.
    A local worker process that dies (killed, out of memory) costs only the episodes not
    finished: they run again in a fresh pool, and if lost again
    :class:`homing_train.pool.WorkerDiedError` names their seeds. SIGTERM and SIGHUP end
    the run as Ctrl-C does (:class:`homing_train.pool.Stopped`)."""
    for task in tasks:
        if not 1 <= len(task) <= 3:
            raise ValueError(f"a task is (seed, start, home), got {task!r}")
    if workers < 1:
        raise ValueError(f"workers must be >= 1, got {workers}")
    if backend not in BACKENDS:
        raise ValueError(f"unknown backend {backend!r}; allowed: {BACKENDS}")
    if spec.sequential:
        workers, backend = 1, "local"
    bar = tqdm(total=len(tasks), desc=desc, disable=not progress, unit="ep")
    records: list[EpisodeRecord | None] = [None] * len(tasks)
    try:
        if backend == "ray":
            for i, record in _ray_records(spec, env_id, env_kwargs, tasks, workers, address):
                records[i] = record
                if on_record is not None:
                    on_record(record)
                bar.update()
        elif workers == 1 or len(tasks) <= 1:
            _init_worker(spec, env_id, env_kwargs)
            try:
                for i, task in enumerate(tasks):
                    records[i] = _work(task)
                    if on_record is not None:
                        on_record(records[i])
                    bar.update()
            finally:
                env = _WORKER.pop("env", None)
                if env is not None:
                    env.close()
                _WORKER.clear()
        else:
            with contextlib.closing(pool_results(
                    _work, tasks, workers, initializer=_init_worker,
                    initargs=(spec, env_id, env_kwargs),
                    name=lambda task: f"seed {task[0]}")) as finished:
                for i, record in finished:
                    records[i] = record
                    if on_record is not None:
                        on_record(record)
                    bar.update()
    finally:
        bar.close()
    return records  # type: ignore[return-value]


def _indexed_work(item: tuple[int, tuple]) -> tuple[int, EpisodeRecord]:
    return item[0], _work(item[1])


def check_env_id(env_id: str) -> None:
    """``ValueError`` naming ``env_id`` and the package's ids if Gymnasium has no such id,
    or if its entry point is a class that is no :class:`homing_gym.env.HomingEnv` (the
    harness reads a homing env's poses, goals and scene; a factory function is trusted)."""
    ids = list(homing_gym.ENV_IDS)
    if env_id not in gym.registry:
        raise ValueError(f"unknown env id {env_id!r}; homing-gym ids: {ids}")
    creator = _env_creator(env_id)
    if isinstance(creator, type) and not issubclass(creator, HomingEnv):
        raise ValueError(f"env {env_id!r} is not a homing-gym env ({creator.__name__} is no "
                         f"homing_gym.env.HomingEnv): the harness scores homing episodes "
                         f"from the robot's poses and goals; homing-gym ids: {ids}, or an "
                         f"env of yours built on HomingEnv (--import)")


def _env_creator(env_id: str) -> Any:
    """What Gymnasium calls to make ``env_id``: a class or a function."""
    entry = gym.spec(env_id).entry_point
    return gym.envs.registration.load_env_creator(entry) if isinstance(entry, str) else entry


def env_parameters(env_id: str) -> frozenset[str] | None:
    """The keyword arguments the entry point of ``env_id`` names, or ``None`` when it
    takes any (``**kwargs``, as homing-gym's envs do, which check the names themselves)."""
    creator = _env_creator(env_id)
    try:
        parameters = inspect.signature(creator).parameters.values()
    except (TypeError, ValueError):             # a builtin or C callable: cannot tell
        return None
    if any(p.kind is inspect.Parameter.VAR_KEYWORD for p in parameters):
        return None
    return frozenset(p.name for p in parameters
                     if p.kind in (inspect.Parameter.POSITIONAL_OR_KEYWORD,
                                   inspect.Parameter.KEYWORD_ONLY))


def env_default(env_id: str, name: str) -> Any:
    """The default of the argument ``name`` of the env of ``env_id``, or ``None`` when its
    entry point names no such argument with a default."""
    try:
        param = inspect.signature(_env_creator(env_id)).parameters.get(name)
    except (TypeError, ValueError):             # a builtin or C callable: cannot tell
        return None
    return None if param is None or param.default is inspect.Parameter.empty else param.default


def success_rule_setting(env_id: str, env_kwargs: dict[str, Any]) -> dict[str, Any]:
    """``{"success_on": rule}``: the given rule, else the default of the env of
    ``env_id``, for a result to record explicitly; ``{}`` when the env names none."""
    rule = env_kwargs.get("success_on", env_default(env_id, "success_on"))
    return {} if rule is None else {"success_on": rule}


def harness_env_kwargs(env_id: str, env_kwargs: dict[str, Any],
                       added: dict[str, Any]) -> dict[str, Any]:
    """``env_kwargs`` with the harness's ``added`` defaults (e.g. the renderer, recorded
    explicitly) where the env takes them; ``ValueError`` naming every given argument that
    the env of ``env_id`` (e.g. a user's, ``--import``) does not take."""
    takes = env_parameters(env_id)
    if takes is None:
        return {**added, **env_kwargs}
    odd = sorted(set(env_kwargs) - takes)
    if odd:
        raise ValueError(f"env {env_id!r} does not take the arguments {odd}; it takes "
                         f"{sorted(takes - {'render_mode'})}")
    return {**{k: v for k, v in added.items() if k in takes}, **env_kwargs}


def evaluate(policy, env_id: str = DEFAULT_ENV, episodes: int = 100, seed: int = 0,
             env_kwargs: dict[str, Any] | None = None, workers: int = 1,
             params: dict[str, Any] | None = None, bin_width: float = 0.3,
             progress: bool = True, stream: str | None = None,
             resume: bool = False, tasks: Sequence[tuple] | None = None,
             backend: str = "local", address: str | None = None,
             use_record: bool = True) -> EvalResult:
    """Evaluate ``policy`` (controller name, controller, :class:`PolicySpec` or SB3 zip
    path; a zip under the settings recorded beside it, given ``env_kwargs`` and
    ``params`` winning, unless not ``use_record``: a protocol's cell has chosen what of
    the record applies) on episodes seeded ``seed .. seed + episodes - 1``, or on ``tasks``
    ``[(seed, start pose or None, home pose or None), ...]`` (distinct seeds; then
    ``episodes`` and ``seed`` are taken from them).

    ``stream``: a JSON-lines file that gets each finished episode at once (its first line
    the settings), so an interrupted evaluation keeps what it finished; with ``resume``
    the episodes already in it are kept and only the others are run (same settings
    required), giving the records an uninterrupted run would give. ``backend``/``address``:
    see :func:`run_episodes`."""
    if tasks is not None:
        tasks = [tuple(t) + (None,) * (3 - len(t)) for t in tasks]
        seeds = [t[0] for t in tasks]
        if not tasks or len(set(seeds)) != len(seeds):
            raise ValueError(f"tasks must be a non-empty list with distinct seeds, got seeds "
                             f"{seeds[:10]}")
        episodes, seed = len(tasks), seeds[0]
    else:
        seeds = list(range(seed, seed + episodes))
    if episodes < 1:
        raise ValueError(f"episodes must be >= 1, got {episodes}")
    if not (isinstance(workers, int) and workers >= 1):
        raise ValueError(f"workers must be >= 1, got {workers!r}")
    require_positive("bin width", bin_width, "metres")
    check_env_id(env_id)
    spec = policy_spec(policy, params)
    env_kwargs = dict(env_kwargs or {})
    if spec.kind == "sb3" and use_record:
        # a zip is evaluated as it was shipped; explicit settings override the record
        recorded = recorded_settings(spec.source)
        env_kwargs = {**recorded.env_kwargs, **env_kwargs}
        spec = dataclasses.replace(spec, params={**recorded.params, **spec.params})
    # recorded explicitly: the simulation and the success rule
    added = {**simulation_settings(env_kwargs), **success_rule_setting(env_id, env_kwargs)}
    if spec.kind == "controller":
        # what the controller reads; observation keys never change the episodes
        added["obs_keys"] = list(spec.build().observation_keys())
    env_kwargs = harness_env_kwargs(env_id, env_kwargs, added)
    settings = json.loads(json.dumps({"policy": spec.label, "params": spec.resolved_params(),
                                      "env_id": env_id, "env_kwargs": env_kwargs,
                                      **({"tasks": tasks} if tasks is not None else {})},
                                     default=_json_default))
    # one writer per stream: a second run on it fails here, before its first episode
    with OutputLock(stream) if stream else contextlib.nullcontext():
        done = read_stream(stream, settings) if stream and resume else {}
        todo = [t for t in (tasks or [(s, None, None) for s in seeds]) if t[0] not in done]
        sink = open_stream(stream, settings, append=bool(done)) if stream else None
        try:
            fresh = run_episodes(spec, env_id, env_kwargs, todo, workers, progress,
                                 desc=f"{spec.label}",
                                 on_record=None if sink is None else sink.write_record,
                                 backend=backend, address=address)
        finally:
            if sink is not None:
                sink.close()
    records = {r.seed: r for r in fresh} | done
    return EvalResult(policy=spec.label, params=spec.resolved_params(), env_id=env_id,
                      env_kwargs=env_kwargs, seed=seed,
                      episodes=[records[s] for s in seeds],
                      bin_width=bin_width)


class _Stream:
    """An open JSON-lines file of finished episodes, flushed line by line. A new file
    gets its first line (the settings) atomically; appending to an old one first drops
    its torn last line (an interrupted write). A new file that got no episode (the run
    failed before its first one) is removed on close, so that it cannot block a later
    ``--resume`` with other settings."""

    def __init__(self, path: str, settings: dict, append: bool):
        self.path, self.append, self.records = path, append, 0
        if append:
            with open(path, "rb+") as f:
                f.truncate(f.read().rfind(b"\n") + 1)
        else:
            write_text_atomic(path, _json_line(settings))
        self.file = open(path, "a")

    def write_record(self, record: EpisodeRecord) -> None:
        self.file.write(_json_line(asdict(record)))
        self.file.flush()
        self.records += 1

    def close(self) -> None:
        self.file.close()
        if not self.append and not self.records:
            os.remove(self.path)


def _json_line(doc: dict) -> str:
    return json.dumps(doc, default=_json_default) + "\n"


def open_stream(path: str, settings: dict, append: bool = False) -> _Stream:
    """Open the episode stream (``ValueError`` naming the path if it cannot be written)."""
    try:
        return _Stream(path, settings, append)
    except OSError as err:
        raise ValueError(f"cannot write {path!r}: {err.strerror}") from None


def read_stream(path: str, settings: dict) -> dict[int, EpisodeRecord]:
    """The finished episodes of a stream written with the same ``settings``, by seed
    (none if the file does not exist or lacks a whole first line). Its last line, if
    torn by an interrupted write, is ignored; anything else unsound is a ``ValueError``
    naming the file and line: a first line of other settings, a line that is not JSON,
    a record with a missing, mistyped or impossible field
    (:meth:`EpisodeRecord.from_doc`), a seed twice with different content."""
    if not os.path.exists(path):
        return {}
    try:
        with open(path, "rb") as f:
            lines = f.read().decode(errors="replace").split("\n")
    except OSError as err:
        raise ValueError(f"{path}: not a readable episode stream ({err})") from None
    lines.pop()         # "" after the last newline, or a line torn by an interrupted write
    done: dict[int, EpisodeRecord] = {}
    first: dict[int, int] = {}
    for number, line in enumerate(lines, 1):
        where = f"{path} line {number}"
        try:
            doc = json.loads(line)
        except json.JSONDecodeError:
            raise ValueError(f"{where}: not a JSON line (torn or edited), so the stream "
                             f"cannot be resumed; run without --resume to start over") from None
        if number == 1:
            if doc != settings:
                raise ValueError(f"{where}: {path} holds episodes of other settings "
                                 f"({doc!r:.300}); cannot resume with {settings!r:.300}")
            continue
        try:
            record = EpisodeRecord.from_doc(doc)
        except ValueError as err:
            raise ValueError(f"{where}: {err}") from None
        if record.seed in done and done[record.seed] != record:
            raise ValueError(f"{where}: seed {record.seed} again with other content than "
                             f"at line {first[record.seed]}; the stream mixes two runs")
        done[record.seed] = record
        first.setdefault(record.seed, number)
    return done


def stream_path(out: str) -> str:
    """The episode stream beside a result JSON: ``NAME.episodes.jsonl``."""
    return os.path.splitext(out)[0] + ".episodes.jsonl"


# -- command line ---------------------------------------------------------------------------
def add_policy_arguments(parser: argparse.ArgumentParser,
                         controllers_only: bool = False) -> None:
    """The ``--policy/--param/--seed/--workers`` options and the world's
    (:func:`homing_gym.cli.add_env_arguments`: ``--env/--env-kwargs/--scene``);
    ``controllers_only``: the command takes scripted controllers, not model zips.
    ``--seed`` is ``None`` unless given (a protocol has its own)."""
    parser.add_argument("--policy", required=True,
                        help="registered scripted controller name" if controllers_only else
                        "registered controller name or path to a stable-baselines3 .zip")
    parser.add_argument("--param", action="append", default=[], metavar="KEY=VALUE",
                        help="controller parameter override (repeatable)" + (
                            "" if controllers_only else "; for an SB3 model only "
                            "deterministic=false (sample actions, seeded per episode)"))
    add_env_arguments(parser, DEFAULT_ENV)
    parser.add_argument("--seed", type=seed_value, default=None,
                        help="seed of the first episode (default 0; with --protocol: the "
                        "base seed of the protocol's episode draw, default its own)")
    parser.add_argument("--workers", type=worker_count, default=1, help="parallel processes")
    parser.add_argument("--quiet", action="store_true", help="no progress bar")
    parser.add_argument("--trust-policy", action="store_true",
                        help="load a model zip with pickle: RUNS CODE FROM THE FILE (only for "
                        "files you trust; by default zips are read without unpickling)")


def add_backend_arguments(parser: argparse.ArgumentParser) -> None:
    """The ``--backend/--ray-address`` options."""
    parser.add_argument("--backend", choices=BACKENDS, default="local",
                        help="where episodes run: local processes (--workers of them) or Ray "
                        "actors (--workers of them; needs the [ray] extra)")
    parser.add_argument("--ray-address", default=None, metavar="ADDRESS",
                        help="with --backend ray: the cluster to join ('auto': the running "
                        "one; default: start a local Ray)")


def check_backend_arguments(parser: argparse.ArgumentParser,
                            args: argparse.Namespace) -> None:
    """``parser.error`` for ``--ray-address`` without ``--backend ray``, which would
    ignore it."""
    if args.ray_address is not None and args.backend != "ray":
        parser.error(f"--ray-address {args.ray_address!r} needs --backend ray (the local "
                     f"backend runs on this machine)")


def policy_from_args(args: argparse.Namespace) -> PolicySpec:
    params = parse_params(args.param, args.policy) if args.param else {}
    if args.trust_policy:
        if not args.policy.endswith(".zip"):
            raise ValueError("--trust-policy applies to model .zip files only")
        params["trust"] = True
    return policy_spec(args.policy, params)


def format_summary(result: EvalResult) -> str:
    s = result.summary
    lo, hi = s["success_ci"]
    return (f"{result.policy} on {result.env_id}: {s['episodes']} episodes, success "
            f"({success_rule_text(result.success_on)}) "
            f"{100 * s['success_rate']:.1f}% [{100 * lo:.1f}, {100 * hi:.1f}], SPL "
            f"{s['spl']:.3f}, soft-SPL {s['soft_spl']:.3f}, final distance "
            f"{100 * s['final_distance_mean']:.1f} cm (median "
            f"{s['final_distance_cm_median']:.1f}), heading error "
            f"{s['heading_error_deg_mean']:.1f} deg, collisions/episode "
            f"{s['collisions_mean']:.2f}{_route_line(s)}")


def success_rule_text(success_on: str | None) -> str:
    """How results scored under ``success_on`` count a success, in a few words."""
    return {"stop": "stopped at the goal", "reach": "reached the goal"}.get(
        success_on, f"rule {success_on!r}" if success_on else "rule not recorded")


def _route_line(s: dict[str, Any]) -> str:
    """The route part of :func:`format_summary` ("" for a summary without routes)."""
    if "route_episodes" not in s:
        return ""
    error = ("no target left" if s["target_error_mean"] is None else
             f"target error {100 * s['target_error_mean']:.1f} cm (median "
             f"{s['target_error_cm_median']:.1f})")
    return (f"; route: targets reached in order {100 * s['targets_reached_fraction']:.1f}%, "
            f"every target {100 * s['reached_rate']:.1f}% of routes, all targets within the "
            f"radius {100 * s['all_targets_within_radius_rate']:.1f}%, targets finished "
            f"{s['targets_finished_mean']:.1f} per route, {error}")


if __name__ == "__main__":
    raise SystemExit("homing-eval's command line is python -m homing_train.harness.eval_command "
                     "(or the homing-eval command)")
