"""Behaviour cloning of the ``oracle`` on rendered pose pairs: a warm start for policies
that home from a panorama and a goal panorama.

Rolling out episodes to collect imitation data costs a physics step and a render per
sample and gives strongly correlated samples (about 100 per second here). This module gets
them from a *bank* of panoramas instead. A cylindrical panorama taken at heading ``theta``
is the panorama taken at heading 0 at the same place, rolled by ``theta * W / (2 pi)``
columns towards higher column indices (``tests/homing_train/learning/test_pretrain.py`` checks this on rendered
panoramas). So ``N`` panoramas rendered at heading 0 at free floor positions give
``N^2 W^2`` pairs (current view at position ``i`` and heading ``k``, goal view at position
``j`` and heading ``m``). Each pair is labelled with the oracle's action from pose
``(x_i, y_i, k)`` towards home ``j``: its waypoint on the true shortest path (a function
of the two positions, computed once per pair) turned into the env's first discrete or
continuous command (:class:`homing_baselines.motion.MotionHelper`). The home heading never
changes the label, and the current heading only rotates the bearing, so the headings are
drawn afresh for every sample: every pass sees new images.

The bank may span several scenes (``env_kwargs["scene"]`` a list of names: scene instance
``s`` is built by ``scene[s % n]``) and many instances of randomised ones. With
``success_on="stop"`` every second bank position lies near the one before it (up to twice
the success radius), and a pair closer than :data:`STOP_SHARE` of the success radius is
labelled with the stop action: the policy learns to declare arrival.

The policy network is fitted by maximum likelihood of the labels
(:func:`homing_train.learning.imitation.fit`), on fresh samples each chunk; its agreement with the oracle
is measured on pairs from a separate bank of positions. The oracle's ground truth labels
training data only; the policy acts from the two images.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Sequence

import gymnasium as gym
import numpy as np
from tqdm.auto import tqdm

import homing_baselines
from homing_baselines.motion import MotionHelper
from homing_gym.paths import connected
from homing_gym.scenes.base import Scene, clearance
from homing_gym.tasks.base import sample_free_pose
from homing_train.harness.rollout import prepare_policy
from homing_train.learning.imitation import fit

#: Observation keys a bank can produce.
BANK_KEYS = ("panorama", "goal")
#: With ``success_on="stop"``: pairs closer than this share of the success radius are
#: labelled stop (a margin inside the radius for the network's error).
STOP_SHARE = 2 / 3


@dataclass
class PoseBank:
    """Panoramas (uint8 ``(N, H, W, 3)``) rendered at heading 0 at free floor positions
    (``(N, 2)`` metres) of one or more scene instances (``scene_index`` into ``scenes``).
    With ``near > 0`` (metres), entry ``2k + 1`` lies within ``near`` of entry ``2k``."""

    positions: np.ndarray
    panoramas: np.ndarray
    scene_index: np.ndarray
    scenes: list[Scene]
    near: float = 0.0


@dataclass
class PairSet:
    """Pairs of bank entries: the robot's position ``current``, the home ``home`` and the
    oracle's waypoint ``target`` (``(P, 2)`` metres, world frame) from one to the other."""

    current: np.ndarray
    home: np.ndarray
    target: np.ndarray


@dataclass
class PretrainResult:
    """Per chunk: samples fitted so far, mean fit loss, agreement with the oracle on the
    validation pairs (share of samples whose most likely action is the oracle's)."""

    positions: int = 0
    pairs: int = 0
    samples: list[int] = field(default_factory=list)
    loss: list[float] = field(default_factory=list)
    agreement: list[float] = field(default_factory=list)


def near_pose(scene: Scene, anchor: np.ndarray, near: float, rng: np.random.Generator,
              margin: float, tries: int = 100) -> np.ndarray:
    """A heading-0 pose at a uniform distance of at most ``near`` metres from ``anchor``
    (x, y) in a uniform direction, with ``margin`` metres of clearance (``anchor`` itself
    if ``tries`` draws find none)."""
    for _ in range(tries):
        d, a = rng.uniform(0.0, near), rng.uniform(-np.pi, np.pi)
        xy = (float(anchor[0] + d * math.cos(a)), float(anchor[1] + d * math.sin(a)))
        if clearance(scene, xy) >= margin:
            return np.array([xy[0], xy[1], 0.0])
    return np.array([anchor[0], anchor[1], 0.0])


def render_bank(env: gym.Env | Sequence[gym.Env], positions_per_scene: int, scenes: int,
                seed: int, near: float = 0.0, progress: bool = True) -> PoseBank:
    """Render ``positions_per_scene`` heading-0 panoramas in each of ``scenes`` scene
    instances; instance ``s`` is ``env[s % len(env)].reset(seed=seed + s)`` (one env per
    scene name; new worlds for randomised scenes). Positions keep the task's clearance
    from obstacles; with ``near > 0`` (metres) every second one lies within ``near`` of
    the one before (:func:`near_pose`)."""
    envs = [env] if isinstance(env, gym.Env) else list(env)
    if near > 0 and positions_per_scene % 2:
        raise ValueError(f"a bank with near positions needs an even number of positions "
                         f"per scene, got {positions_per_scene}")
    rng = np.random.default_rng(seed)
    positions, panoramas, index, worlds = [], [], [], []
    bar = tqdm(total=scenes * positions_per_scene, desc="rendering pose bank",
               disable=not progress)
    for s in range(scenes):
        world = envs[s % len(envs)]
        world.reset(seed=seed + s)
        unwrapped = world.unwrapped
        margin = float(getattr(unwrapped.task, "clearance_margin", 0.22))
        worlds.append(unwrapped.scene)
        for n in range(positions_per_scene):
            if near > 0 and n % 2:
                pose = near_pose(unwrapped.scene, positions[-1], near, rng, margin)
            else:
                pose = sample_free_pose(unwrapped.scene, rng, margin)
                pose[2] = 0.0
            unwrapped.sim.robot.set_pose(*pose)
            panoramas.append(unwrapped.render_panorama(pose))
            positions.append(pose[:2])
            index.append(s)
            bar.update()
    bar.close()
    return PoseBank(np.asarray(positions), np.asarray(panoramas), np.asarray(index), worlds,
                    near)


def pair_set(bank: PoseBank, n_pairs: int, distance: tuple[float, float], oracle,
             rng: np.random.Generator, radius: float, progress: bool = True) -> PairSet:
    """``n_pairs`` (current, home) pairs from the same scene instance, ``distance`` =
    (min, max) metres apart and joined by a path for a disc of ``radius`` metres (the
    task's ``path_radius``: the episodes' own rule), with the oracle's waypoint for each."""
    lo, hi = distance
    current, home, target = [], [], []
    bar = tqdm(total=n_pairs, desc="labelling pose pairs", disable=not progress)
    while len(current) < n_pairs:
        j = int(rng.integers(len(bank.positions)))
        d = np.linalg.norm(bank.positions - bank.positions[j], axis=1)
        candidates = np.flatnonzero((d >= lo) & (d <= hi)
                                    & (bank.scene_index == bank.scene_index[j]))
        if len(candidates) == 0:
            continue
        i = int(rng.choice(candidates))
        scene = bank.scenes[bank.scene_index[i]]
        pose = (*bank.positions[i], 0.0)
        home_pose = (*bank.positions[j], 0.0)
        if not connected(scene, pose, home_pose, radius):
            continue
        oracle.reset()
        target.append(oracle.waypoint(scene, pose, home_pose))
        current.append(i)
        home.append(j)
        bar.update()
    bar.close()
    return PairSet(np.asarray(current), np.asarray(home), np.asarray(target, dtype=float))


def near_pairs(bank: PoseBank, oracle) -> PairSet:
    """Both ways between the near neighbours of ``bank`` (entries ``2k`` and ``2k + 1``,
    ``bank.near > 0``), each with the oracle's waypoint."""
    if bank.near <= 0:
        raise ValueError("near_pairs needs a bank rendered with near > 0")
    even = np.arange(0, len(bank.positions), 2)
    current = np.concatenate([even, even + 1])
    home = np.concatenate([even + 1, even])
    target = []
    for i, j in zip(current, home):
        oracle.reset()
        target.append(oracle.waypoint(bank.scenes[bank.scene_index[i]],
                                      (*bank.positions[i], 0.0), (*bank.positions[j], 0.0)))
    return PairSet(current, home, np.asarray(target, dtype=float))


def joined(a: PairSet, b: PairSet) -> PairSet:
    """The pairs of ``a`` then those of ``b``."""
    return PairSet(np.concatenate([a.current, b.current]), np.concatenate([a.home, b.home]),
                   np.concatenate([a.target, b.target]))


def rolled(panoramas: np.ndarray, columns: np.ndarray) -> np.ndarray:
    """``panoramas[n]`` rolled by ``columns[n]`` columns (``np.roll`` along azimuth): the
    view at the same place after turning ``columns[n] * 2 pi / W`` radians
    counter-clockwise."""
    n, height, width, _ = panoramas.shape
    cols = (np.arange(width)[None, :] - columns[:, None]) % width
    return panoramas[np.arange(n)[:, None, None], np.arange(height)[None, :, None],
                     cols[:, None, :]]


def pair_labels(bank: PoseBank, pairs: PairSet, p: np.ndarray, k: np.ndarray, oracle,
                helper: MotionHelper, stop_radius: float = 0.0) -> np.ndarray:
    """The oracle's first action for pairs ``p`` with the robot at heading ``k`` columns
    (``k * 2 pi / W`` radians, counter-clockwise); the stop action for pairs closer than
    ``stop_radius`` metres."""
    width = bank.panoramas.shape[2]
    labels = []
    for pair, column in zip(p, k):
        here, home = bank.positions[pairs.current[pair]], bank.positions[pairs.home[pair]]
        if np.linalg.norm(here - home) < stop_radius:
            labels.append(helper.stop_action())
            continue
        pose = (*here, column * 2 * math.pi / width)
        actions = helper.plan(oracle.move_to(pose, pairs.target[pair]))
        labels.append(actions[0] if actions else helper.stop_action())
    return np.asarray(labels)


def pair_samples(bank: PoseBank, pairs: PairSet, count: int, oracle, helper: MotionHelper,
                 rng: np.random.Generator, stop_radius: float = 0.0
                 ) -> tuple[dict[str, np.ndarray], np.ndarray]:
    """``count`` samples: a random pair with random current and home headings (whole
    columns), as observations ``{"panorama", "goal"}`` and the oracle's first action
    (:func:`pair_labels`, stop within ``stop_radius`` metres)."""
    width = bank.panoramas.shape[2]
    p = rng.integers(len(pairs.current), size=count)
    k = rng.integers(width, size=count)
    m = rng.integers(width, size=count)
    observations = {"panorama": rolled(bank.panoramas[pairs.current[p]], k),
                    "goal": rolled(bank.panoramas[pairs.home[p]], m)}
    return observations, pair_labels(bank, pairs, p, k, oracle, helper, stop_radius)


def agreement(model, observations: dict[str, np.ndarray], labels: np.ndarray,
              batch_size: int = 512) -> float:
    """Share of samples whose deterministic policy action equals the label."""
    hits = 0
    for start in range(0, len(labels), batch_size):
        batch = {k: v[start:start + batch_size] for k, v in observations.items()}
        actions, _ = model.predict(batch, deterministic=True)
        hits += int(np.sum(np.all(np.reshape(actions == labels[start:start + batch_size],
                                             (len(actions), -1)), axis=1)))
    return hits / len(labels)


def pretrain(model, env_id: str, env_kwargs: dict, positions: int, scenes: int,
             samples: int, seed: int, chunk: int = 8192, batch_size: int = 128,
             progress: bool = True) -> PretrainResult:
    """Fit ``model`` (SB3 PPO with a ``{"panorama", "goal"}`` observation) to the oracle on
    ``samples`` rendered pair samples from ``positions`` bank positions spread over
    ``scenes`` scene instances (seeds from ``seed``; ``env_kwargs["scene"]`` may be a list
    of scene names, taken in turn); validation pairs come from a separate bank of a
    quarter of the size (seeds from ``seed + scenes``). With ``success_on="stop"`` the
    banks hold near positions and pairs closer than :data:`STOP_SHARE` of the success
    radius are labelled stop."""
    if positions < 2 * scenes or scenes < 1 or samples < 1:
        raise ValueError(f"pretraining needs scenes >= 1, positions >= 2 per scene and "
                         f"samples >= 1, got positions={positions}, scenes={scenes}, "
                         f"samples={samples}")
    names = env_kwargs.get("scene")
    if isinstance(names, list) and (not names or scenes < len(names)):
        raise ValueError(f"pretraining on a list of scenes needs a non-empty list and at "
                         f"least one instance of each (pretrain_scenes >= {len(names)}), "
                         f"got scene={names!r}, scenes={scenes}")
    envs = [gym.make(env_id, **{**env_kwargs, "scene": name}) for name in names] \
        if isinstance(names, list) else [gym.make(env_id, **env_kwargs)]
    try:
        keys = tuple(envs[0].observation_space.spaces)
        if sorted(keys) != sorted(BANK_KEYS):
            raise ValueError(f"pretraining on pose pairs needs obs_keys {BANK_KEYS}, the "
                             f"env has {keys}")
        oracle = homing_baselines.make("oracle")
        prepare_policy(oracle, envs[0])
        helper = MotionHelper(oracle.motion_spec, oracle.motion)
        task = envs[0].unwrapped.task
        stop = task.success_on == "stop"
        near = 2 * task.success_radius if stop else 0.0
        stop_radius = STOP_SHARE * task.success_radius if stop else 0.0
        distance = (task.success_radius, task.start_distance[1])
        rng = np.random.default_rng(seed)
        per_scene = positions // scenes
        per_check = max(per_scene // 4, 2)
        bank = render_bank(envs, per_scene - per_scene % 2 if stop else per_scene, scenes,
                           seed, near, progress)
        check = render_bank(envs, per_check - per_check % 2 if stop else per_check, scenes,
                            seed + scenes, near, progress)
    finally:
        for env in envs:
            env.close()
    pairs = pair_set(bank, 8 * positions, distance, oracle, rng, task.path_radius, progress)
    check_pairs = pair_set(check, 2 * len(check.positions), distance, oracle, rng,
                           task.path_radius, progress)
    if stop:
        pairs = joined(pairs, near_pairs(bank, oracle))
        check_pairs = joined(check_pairs, near_pairs(check, oracle))
    check_obs, check_labels = pair_samples(check, check_pairs, 4096, oracle, helper, rng,
                                           stop_radius)
    result = PretrainResult(positions=len(bank.positions), pairs=len(pairs.current))
    done = 0
    bar = tqdm(total=samples, desc="pretraining on pose pairs", disable=not progress)
    while done < samples:
        n = min(chunk, samples - done)
        observations, labels = pair_samples(bank, pairs, n, oracle, helper, rng, stop_radius)
        result.loss.append(fit(model, observations, labels, 1, batch_size, rng))
        done += n
        result.samples.append(done)
        result.agreement.append(agreement(model, check_obs, check_labels))
        bar.update(n)
        bar.set_postfix(loss=f"{result.loss[-1]:.3f}", agree=f"{result.agreement[-1]:.2f}")
    bar.close()
    return result
