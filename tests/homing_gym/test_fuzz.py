"""Fuzz: a seeded sample of bad constructor arguments and actions for every env id, and
bad inputs to every command, each case in its own subprocess with a timeout, must end in
a clear error.

An env case makes the env, resets it and steps it; the outcome is one of ``clear`` (a
``ValueError``/``TypeError`` or Gymnasium error whose message names the bad argument, or
says ``action`` for a bad action), ``vague`` (such an error that names neither),
``accepted`` (no error:
for a bad input, silently accepted), ``deep`` (any other exception, from deep inside
PyBullet or numpy), ``crash`` (the process died) or ``hang`` (past the timeout). A command
case is ``clear`` when the command exits with status 2 and says ``error:`` without a
traceback, ``accepted`` when it exits 0, ``crash`` for any other ending.
``python tests/homing_gym/test_fuzz.py`` prints the counts.

Documented acceptance: ``gym.make(..., max_episode_steps=-1)`` is Gymnasium's way of
asking for no time limit (the env cards in ``docs/envs/``), so it is not counted as a bad input.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import zipfile
from collections import Counter
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest

ENV_IDS = ("homing_gym/LocalHoming-v0", "homing_gym/RouteFollowing-v0",
           "homing_gym/LongRangeHoming-v0", "homing_gym/LandmarkNavigation-v0",
           "homing_gym/WorkLocations-v0")
NAN, INF = "nan", "inf"   # JSON-safe stand-ins, turned into floats in the case script
BAD_KWARGS = [
    {"physics_substeps": 0}, {"physics_substeps": 10**8}, {"physics_substeps": 2.5},
    {"physics_substeps": "24"}, {"control_period": 0}, {"control_period": 1e5},
    {"control_period": NAN}, {"control_period": "0.1"}, {"max_speed": -1},
    {"max_speed": NAN}, {"max_yaw_rate": INF}, {"panorama_shape": [-48, 256]},
    {"panorama_shape": [48]}, {"panorama_shape": "48x256"}, {"panorama_shape": [100000, 64]},
    {"success_radius": 0}, {"success_radius": -1}, {"success_radius": NAN},
    {"lighting_change": -1}, {"lighting_change": 2}, {"lighting_change": NAN},
    {"obs_keys": []}, {"obs_keys": ["nope"]}, {"obs_keys": ["panorama", "panorama"]},
    {"action_type": "nope"}, {"render_mode": "ascii"}, {"odometry_noise": -1},
    {"scene": "nowhere"}, {"scene": 5}, {"reward": {"nope": 1}},
    {"reward": {"progress": "x"}}, {"reward": {"progress": NAN}}, {"stop_threshold": 2},
    {"vfov_deg": 500}, {"renderer": "nope"}, {"omni_size": 3},
    {"max_episode_steps": 0}, {"max_episode_steps": 2.5}, {"odometry_origin": "goal"},
    {"drive": "tank"}, {"drive": "synchro", "action_type": "discrete"},
    {"panorama_shape": 48}, {"sky_color": 5}, {"camera_height": "0.3"}, {"bogus": 1},
    {"max_speed": 1e9}, {"supersampling": True}, {"obs_keys": "panorama"},
    {"success_radius": 1e6}, {"n_targets": 10**9}, {"n_targets": True},
    {"episodes_per_world": True}, {"episodes_per_world": 10**30}, {"physics_substeps": True},
    {"odometry_noise": 1e9}, {"spacing": 1e-9}, {"start_jitter": [0.05, 1e9]},
    {"n_views": 6.0}, {"goal_step_length": NAN}, {"camera_height": INF}, {"vfov_deg": NAN},
    {"max_speed": True}, {"scene": "mesh:room.obj?&&"},
    {"scene": "mesh:room.obj?scale=1&scale=2"}, {"scene": "mesh:/"},
]
BAD_COMMANDS = [   # (module of the command, arguments)
    ("homing_train.harness.eval_command", ["--policy", "nope", "--out", "{tmp}/r.json"]),
    ("homing_train.harness.eval_command", ["--policy", "random", "--episodes", "0",
                                       "--out", "{tmp}/r.json"]),
    ("homing_train.harness.eval_command", ["--policy", "random", "--env", "nope/Nope-v0",
                                       "--out", "{tmp}/r.json"]),
    ("homing_train.harness.eval_command", ["--policy", "random", "--env-kwargs", "{bad json",
                                       "--out", "{tmp}/r.json"]),
    ("homing_train.harness.eval_command", ["--policy", "random", "--workers", "2", "--env-kwargs",
                                       '{"scene": "nowhere"}', "--out", "{tmp}/r.json"]),
    ("homing_train.harness.eval_command", ["--policy", "random", "--param", "no_equals_sign",
                                       "--out", "{tmp}/r.json"]),
    ("homing_train.harness.eval_command", ["--policy", "{tmp}/missing.zip", "--out",
                                       "{tmp}/r.json"]),
    ("homing_train.harness.eval_command", ["--policy", "random", "--out", "/proc/none/r.json"]),
    ("homing_train.harness.eval_command", ["--policy", "random", "--workers", "0",
                                       "--out", "{tmp}/r.json"]),
    ("homing_train.harness.eval_command", ["--policy", "random", "--import", "no_such_module",
                                       "--out", "{tmp}/r.json"]),
    ("homing_train.harness.suite", ["--methods", "nope", "--out", "{tmp}/suite"]),
    ("homing_train.harness.suite", ["--episodes", "0", "--out", "{tmp}/suite"]),
    ("homing_train.harness.field", ["--policy", "nope", "--out", "{tmp}/f.png"]),
    ("homing_train.harness.field", ["--policy", "warping", "--grid", "-1",
                                    "--out", "{tmp}/f.png"]),
    ("homing_train.harness.compare", ["{tmp}/missing.json", "--out", "{tmp}/cmp"]),
    ("homing_train.harness.demo", ["--scene", "nowhere", "--out", "{tmp}/demo"]),
    ("homing_train.learning.train", ["--env", "nope/Nope-v0", "--out", "{tmp}/run"]),
    ("homing_train.learning.train", ["--timesteps", "-5", "--out", "{tmp}/run"]),
    ("homing_train.learning.train", ["--hp", "n_stepz=64", "--out", "{tmp}/run"]),
    # homing-train's run folder and settings: checked before any work
    ("homing_train.learning.train", ["--out", "", "--timesteps", "64"]),
    ("homing_train.learning.train", ["--out", "/proc/none/run", "--timesteps", "64"]),
    ("homing_train.learning.train", ["--out", "/dev/null", "--timesteps", "64"]),
    ("homing_train.learning.train", ["--resume", "{tmp}"]),
    ("homing_train.learning.train", ["--resume", "{tmp}", "--out", "{tmp}/run"]),
    ("homing_train.learning.train", ["--hp", "policy_kwargs={nope: 1}", "--out", "{tmp}/run"]),
    ("homing_train.learning.train", ["--hp", "policy_kwargs={net_arch: [1000000000]}",
                                     "--n-envs", "1", "--vec", "dummy", "--out", "{tmp}/run"]),
    ("homing_gym.benchmark", ["--steps", "0"]),
    # worker counts, backends and envs that cannot run (tests/.../test_faults_pool.py: the
    # pool's faults, broken --import modules, Ray addresses that are not Ray)
    ("homing_train.harness.field", ["--policy", "warping", "--workers", "0", "--no-return",
                                    "--out", "{tmp}/f.png"]),
    ("homing_train.harness.suite", ["--workers", "0", "--out", "{tmp}/suite"]),
    ("homing_gym.benchmark", ["--workers", "-1"]),
    ("homing_train.harness.eval_command", ["--policy", "random", "--workers", "two",
                                           "--out", "{tmp}/r.json"]),
    ("homing_train.harness.eval_command", ["--policy", "random", "--ray-address", "auto",
                                           "--out", "{tmp}/r.json"]),
    ("homing_train.harness.suite", ["--ray-address", "127.0.0.1:6379", "--out", "{tmp}/s"]),
    ("homing_train.harness.eval_command", ["--policy", "random", "--backend", "ray",
                                           "--ray-address", "auto", "--out", "{tmp}/r.json"]),
    ("homing_train.harness.eval_command", ["--policy", "random", "--env", "CartPole-v1",
                                           "--out", "{tmp}/r.json"]),
    ("homing_train.harness.field", ["--policy", "warping", "--env", "CartPole-v1",
                                    "--no-return", "--out", "{tmp}/f.png"]),
    ("homing_train.harness.demo", ["--env", "CartPole-v1", "--out", "{tmp}/demo"]),
    ("homing_gym.benchmark", ["--renderers", "nope"]),
    ("homing_gym.benchmark", ["--steps", "10", "--json", "/proc/none/b.json"]),
    ("homing_train.harness.eval_command", ["--policy", "random", "--seed", "-1",
                                           "--out", "{tmp}/r.json"]),
    ("homing_train.harness.eval_command", ["--policy", "random", "--env-kwargs",
                                           '{"bogus": 1}', "--out", "{tmp}/r.json"]),
    ("homing_train.harness.suite", ["--env", "nope/Nope-v0", "--out", "{tmp}/suite"]),
    ("homing_train.harness.field", ["--policy", "warping", "--grid", "1e-6", "--no-return",
                                    "--out", "{tmp}/f.png"]),
    # outputs checked before any work (cwd is {tmp}); methods that cannot run where asked
    ("homing_train.harness.eval_command", ["--policy", "random", "--out", ""]),
    ("homing_train.harness.eval_command", ["--policy", "random", "--out", "{tmp}"]),
    ("homing_train.harness.eval_command", ["--policy", "random", "--out", "/dev/null/r.json"]),
    ("homing_train.harness.field", ["--policy", "warping", "--no-return",
                                    "--out", "{tmp}/f.txt"]),
    ("homing_train.harness.suite", ["--methods", "oracle", "--out", "/dev/null"]),
    ("homing_train.harness.compare", ["{tmp}/missing.json", "--out", "/dev/null"]),
    ("homing_train.harness.demo", ["--out", "/dev/null"]),
    ("homing_train.harness.suite", ["--arena", "--methods", "bearing", "--out", "{tmp}/suite"]),
    ("homing_train.harness.suite", ["--protocols", "hong1991", "--methods", "multires",
                                    "--out", "{tmp}/m"]),
    ("homing_train.harness.eval_command", ["--protocol", "hong1991", "--policy", "multires",
                                           "--out", "{tmp}/c.json"]),
    ("homing_train.harness.eval_command", ["--policy", "{tmp}/huge_obs.zip", "--out",
                                           "{tmp}/r.json"]),
    ("homing_train.harness.eval_command", ["--policy", "{tmp}/huge_net.zip", "--out",
                                           "{tmp}/r.json"]),
    ("homing_train.harness.eval_command", ["--policy", "{tmp}/unknown_key.zip", "--out",
                                           "{tmp}/r.json"]),
    ("homing_train.harness.eval_command", ["--policy", "{tmp}/run/model.zip", "--out",
                                           "{tmp}/r.json"]),
]
#: Policy files from others that command cases name as ``{tmp}/NAME``: the shipped
#: ppo_procedural_long.zip's data and weights with ``data[entry][key] = value``, or as
#: shipped (``None``) in a run folder whose ``config.yml`` is not YAML.
POLICY_FILES = {
    "huge_obs.zip": ("observation_space", "spaces", "{'goal': Box(0, 255, (100000, 100000, "
                     "3), uint8), 'panorama': Box(0, 255, (3, 16, 64), uint8)}"),
    "huge_net.zip": ("policy_kwargs", "net_arch", "[1000000000]"),
    "unknown_key.zip": ("policy_kwargs", "bogus", "1"),
    "run/model.zip": None,
}
BAD_ACTIONS = {"continuous": [[NAN, 0], [INF, 0], None, "forward", [1, 2, 3], [True, False],
                              {"complex": [0.5, 1]}],
               "discrete": [NAN, INF, None, "1", 7, -1, 2.5, True]}

CASE_SCRIPT = """
import json, math, sys
import gymnasium as gym, numpy as np, homing_gym
case = json.loads(sys.argv[1])
def real(v):
    if v in ("nan", "inf"): return float(v)
    if isinstance(v, list): return [real(x) for x in v]
    if isinstance(v, dict) and set(v) == {"complex"}: return np.array(v["complex"]) + 1j
    if isinstance(v, dict): return {k: real(x) for k, x in v.items()}
    return v
try:
    env = gym.make(case["env_id"], **real(case["kwargs"]))
    env.reset(seed=0)
    for _ in range(2):
        env.step(real(case["action"]) if "action" in case else env.action_space.sample())
    env.close()
    print(json.dumps(["accepted", ""]))
except (ValueError, TypeError, gym.error.Error) as err:
    names = [*case["kwargs"], *(["action"] if "action" in case else [])]
    named = any(name.lower() in str(err).lower() for name in names)
    print(json.dumps(["clear" if named else "vague", f"{type(err).__name__}: {err}"]))
except Exception as err:
    print(json.dumps(["deep", f"{type(err).__name__}: {err}"]))
"""


def cases(n_kwargs: int | None = None, seed: int = 0) -> list[dict]:
    """A seeded sample of ``n_kwargs`` constructor cases (default: all) over the env ids,
    and every bad action."""
    rng = np.random.default_rng(seed)
    out = [{"env_id": ENV_IDS[int(rng.integers(len(ENV_IDS)))],
            "kwargs": BAD_KWARGS[int(i)]}
           for i in rng.permutation(len(BAD_KWARGS))[:n_kwargs]]
    for action_type, actions in BAD_ACTIONS.items():
        for action in actions:
            out.append({"env_id": "homing_gym/LocalHoming-v0",
                        "kwargs": {"action_type": action_type, "panorama_shape": [16, 64]},
                        "action": action})
    return out


def run_case(case: dict, timeout: float = 60.0) -> tuple[str, str]:
    """``(outcome, message)`` of one case in a fresh interpreter."""
    try:
        out = subprocess.run([sys.executable, "-c", CASE_SCRIPT, json.dumps(case)],
                             capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        return "hang", f"no answer in {timeout} s"
    lines = out.stdout.strip().splitlines()
    if out.returncode != 0 or not lines:
        return "crash", (out.stderr.strip().splitlines() or ["exit %d" % out.returncode])[-1]
    outcome, message = json.loads(lines[-1])
    return outcome, message


def write_policy_files(folder: str) -> None:
    """The files of :data:`POLICY_FILES` under ``folder``."""
    from homing_train.harness.policies import POLICY_DIR

    with zipfile.ZipFile(POLICY_DIR / "ppo_procedural_long.zip") as source:
        data, weights = json.loads(source.read("data")), source.read("policy.pth")
    os.makedirs(os.path.join(folder, "run"))
    with open(os.path.join(folder, "run", "config.yml"), "w") as config:
        config.write("env_kwargs: [1, 2\n")
    for name, edit in POLICY_FILES.items():
        edited = dict(data)
        if edit is not None:
            entry, key, value = edit
            edited[entry] = {**data[entry], key: value}
        with zipfile.ZipFile(os.path.join(folder, name), "w") as out:
            out.writestr("data", json.dumps(edited))
            out.writestr("policy.pth", weights)


def run_command_case(case: dict, timeout: float = 120.0) -> tuple[str, str]:
    """``(outcome, message)`` of one command case (``{"module", "args"}``) in a fresh
    interpreter, its output files under a temporary folder."""
    with tempfile.TemporaryDirectory() as tmp:
        if any(arg.removeprefix("{tmp}/") in POLICY_FILES for arg in case["args"]):
            write_policy_files(tmp)
        args = [a.replace("{tmp}", tmp) for a in case["args"]]
        try:
            out = subprocess.run([sys.executable, "-m", case["module"], *args],
                                 capture_output=True, text=True, timeout=timeout, cwd=tmp)
        except subprocess.TimeoutExpired:
            return "hang", f"no answer in {timeout} s"
    last = (out.stderr.strip().splitlines() or [""])[-1]
    if out.returncode == 0:
        return "accepted", out.stdout.strip()[-160:]
    if out.returncode == 2 and "error:" in last and "Traceback" not in out.stderr:
        return "clear", last
    return "crash", f"exit {out.returncode}: {last}"


def command_cases() -> list[dict]:
    return [{"module": module, "args": args} for module, args in BAD_COMMANDS]


def run_all(workers: int = 2) -> list[tuple[dict, str, str]]:
    sample = cases() + command_cases()
    run = lambda case: (run_command_case if "module" in case else run_case)(case)  # noqa: E731
    with ThreadPoolExecutor(workers) as pool:
        results = list(pool.map(run, sample))
    return [(case, *result) for case, result in zip(sample, results)]


@pytest.mark.slow
def test_every_bad_input_gets_a_clear_error():
    results = run_all()
    bad = [(case, outcome, message) for case, outcome, message in results
           if outcome != "clear"]
    assert bad == [], "\n".join(f"{o}: {c} -> {m}" for c, o, m in bad)


def test_max_episode_steps_minus_one_is_gymnasiums_no_time_limit():
    import gymnasium as gym

    import homing_gym  # noqa: F401

    env = gym.make("homing_gym/LocalHoming-v0", max_episode_steps=-1,
                   panorama_shape=(16, 64))
    try:
        assert env.spec.max_episode_steps is None
        wrapper = env
        while wrapper is not env.unwrapped:
            assert not isinstance(wrapper, gym.wrappers.TimeLimit)
            wrapper = wrapper.env
    finally:
        env.close()


if __name__ == "__main__":
    results = run_all()
    counts = Counter(outcome for _, outcome, _ in results)
    print(f"tried {len(results)}: " + ", ".join(f"{k} {counts.get(k, 0)}" for k in
                                                ("clear", "vague", "accepted", "deep", "crash",
                                                 "hang")))
    for case, outcome, message in results:
        if outcome != "clear":
            print(f"  {outcome}: {case} -> {message[:160]}")
