"""``homing-suite``: the package's main job, the comparison of every method.

    homing-suite                # the headline: held-out worlds and the papers' protocols
    homing-suite --episodes 20 --out results/headline
    homing-suite --protocols all --workers 2 --out results/matrix
    homing-suite --arena        # every method on LocalHoming-v0 in Yu & Kim's arena
    homing-suite --scene mesh:world.obj --env-kwargs '{"max_episode_steps": 300}'

With no arguments it runs the headline comparison
(:mod:`homing_train.harness.headline`): the held-out worlds (``unseen``,
``local-common``) and the papers' protocols, every classical method where it applies
and the default learned policy (``ppo_procedural_long``), a few episodes per protocol
(about 4 minutes on 2 cores); it prints the methods x protocols table (success with 95%
intervals and the episodes per cell) and a reading of it, and writes the matrix files
and each cell's files into ``--out``. ``--episodes N`` runs N per setting of every protocol instead,
``--methods`` a subset (a shipped policy by name too; in the one-env comparison also a
PPO model zip by path, e.g. ``runs/RUN/model.zip``, under its recorded input format).

``--protocols NAME ...`` (``all``: every protocol, the paper-like counts) runs every
applicable method on each protocol (:mod:`homing_train.harness.protocols`, one success
rule: stopped within the radius) and writes the methods x protocols matrix
(:mod:`homing_train.harness.matrix`): ``matrix.md`` (printed; every cell with the
``homing-eval --protocol`` command that reproduces it), ``.csv``, ``.json``, ``.png``.

``--arena``, or any of ``--env``/``--env-kwargs``/``--scene``/``--success-on``, runs the
one-env comparison instead: every registered scripted controller made for the env and
its scene (:func:`suite_methods`) and every shipped PPO policy trained on the env
(``train/shipped/*.zip`` with the evaluation settings of its ``*.yml``:
``eval_env_kwargs``, ``eval_params``, and the controllers' time:
:func:`~homing_train.harness.matrix.equal_time_kwargs`), every row under the same
``--env-kwargs``/``--scene``, with the same harness on the same seeded episodes (episode
``i`` uses seed ``seed + i``; default 20 episodes of LocalHoming-v0 in its default scene,
Yu & Kim's arena with homes anywhere), writes one ``<method>.json``/``.csv`` per method
into ``--out``, then runs ``homing-compare`` on them:
``table.md`` (printed), ``success_vs_distance.png``, ``final_distance.png`` and
``trajectories.png``.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path
from typing import Any

import gymnasium as gym
import homing_baselines
import homing_gym  # noqa: F401  (registers the env ids)
from homing_gym.cli import (add_env_arguments, command_parser, env_kwargs_from_args,
                            seed_value, worker_count)
from homing_train.extras import missing_extra
from homing_train.harness.compare import compare
from homing_train.harness.evaluate import (DEFAULT_ENV, add_backend_arguments,
                                           check_backend_arguments, check_env_id,
                                           evaluate, format_summary, stream_path)
from homing_train.harness.headline import (check_methods, headline_plan, headline_table,
                                           reading)
from homing_train.harness.matrix import (BASE_PERIOD, applicable, equal_time_kwargs,
                                         matrix_markdown, run_matrix)
from homing_train.harness.policies import (DEFAULT_POLICY, model_zips, resolved_name,
                                           shipped_policies)
from homing_train.harness.protocols import PROTOCOLS, protocol
from homing_gym.outputs import OutputLock, output_dir_argument
from homing_train.pool import WorkerDiedError, end_stopped_command

#: ``--workers``' default: 2 where the machine has 2 cores or more.
DEFAULT_WORKERS = min(2, os.cpu_count() or 1)

def suite_methods(env_id: str, env_kwargs: dict[str, Any] | None = None) -> list[str]:
    """The registered controllers made for ``env_id`` in the scene that ``env_kwargs``
    give it (default: its default scene; :meth:`baselines.Controller.made_for`): e.g.
    ``multires`` only on WorkLocations-v0, the colour-identity bearing laws only in the
    ``lab``. Making the env checks ``env_kwargs``."""
    scene = scene_name(env_id, env_kwargs)
    return [name for name in homing_baselines.available()
            if homing_baselines.controller_class(name).made_for(env_id, scene)]


def scene_name(env_id: str, env_kwargs: dict[str, Any] | None = None) -> str:
    """The name of the scene that ``env_kwargs`` give ``env_id`` (made to find it out)."""
    env = gym.make(env_id, **(env_kwargs or {}))
    try:
        return env.unwrapped.scene.name
    finally:
        env.close()


def result_stem(method: str) -> str:
    """The file name (without extension) of ``method``'s results: its name, or for a
    model zip its path without ``.zip``, ``/`` as ``_`` (``runs/a/model.zip`` ->
    ``runs_a_model``)."""
    if not method.endswith(".zip"):
        return method
    return Path(method).with_suffix("").as_posix().lstrip("./").replace("/", "_")


def run_suite(out: Path, env_id: str = DEFAULT_ENV, episodes: int = 20, seed: int = 0,
              workers: int = 2, methods: list[str] | None = None, backend: str = "local",
              address: str | None = None, success_on: str = "stop",
              env_kwargs: dict[str, Any] | None = None,
              resume: bool = False) -> dict[str, str]:
    """Evaluate the methods (default: all controllers and shipped policies made for the
    env and its scene) and compare, every row with the same success rule ``success_on``
    (``"stop"``: the agent stopped at the goal, the protocols' rule; ``"reach"``: came
    within the radius at any time) and the same ``env_kwargs`` (e.g. the scene), a
    learned row under them as in a protocol's setting
    (:func:`~homing_train.harness.matrix.equal_time_kwargs`: its own input format and
    control period, and the controllers' time). Each method's episodes are streamed to
    ``<method>.episodes.jsonl`` as they end, so an interrupt keeps them; with ``resume``
    those already there are kept and only the others run. Of ``methods``, a controller
    not made for the env and its scene is left out with a note (``ValueError`` if none
    is left)."""
    if success_on not in ("stop", "reach"):
        raise ValueError(f"unknown success rule {success_on!r}; allowed: 'stop', 'reach'")
    check_env_id(env_id)
    env_kwargs = dict(env_kwargs or {})
    if "success_on" in env_kwargs:
        raise ValueError(f"env kwargs set success_on={env_kwargs['success_on']!r}; the suite's "
                         f"one success rule is --success-on (stop or reach)")
    policies = {name: p for name, p in {**shipped_policies(), **model_zips(methods)}.items()
                if p.env_id in (None, env_id)}
    if policies and (hint := missing_extra("train")):
        print(f"homing-suite: the learned rows {sorted(policies)} are left out ({hint})")
        policies = {}
    made_for = suite_methods(env_id, env_kwargs)
    candidates = homing_baselines.available() + sorted(policies)
    chosen = methods or made_for + sorted(policies)
    unknown = sorted(set(chosen) - set(candidates))
    if unknown:
        raise ValueError(f"unknown methods {unknown}; available: {candidates}, or the path "
                         f"of a PPO model .zip trained on {env_id}")
    chosen = applicable(chosen, set(made_for) | set(policies),
                        lambda: f"{env_id} in scene {scene_name(env_id, env_kwargs)!r}")
    learned = sorted(set(chosen) & set(policies))
    out.mkdir(parents=True, exist_ok=True)
    paths = []
    setting = {**env_kwargs, "success_on": success_on}   # one rule for every row
    for name in chosen:
        shipped = policies.get(name)
        policy, kwargs, params = (
            str(shipped.path),
            equal_time_kwargs(setting, shipped.env_kwargs, gym.spec(env_id).max_episode_steps),
            shipped.params) if shipped else (name, setting, {})
        path = out / f"{result_stem(name)}.json"
        result = evaluate(policy, env_id, episodes=episodes, seed=seed, env_kwargs=kwargs,
                          workers=workers, params=params, backend=backend, address=address,
                          stream=stream_path(str(path)), resume=resume, use_record=False)
        print(format_summary(result))
        result.save(str(path))
        paths.append(str(path))
    return compare(paths, str(out))


def main(argv: list[str] | None = None) -> int:
    parser = command_parser("homing-suite", __doc__)
    parser.add_argument("--protocols", nargs="+", metavar="NAME",
                        help="run the methods x protocols matrix on these protocols ('all': "
                        f"every one of {sorted(PROTOCOLS)}) instead of the headline's; "
                        "--episodes then counts per setting (default: each protocol's)")
    parser.add_argument("--arena", action="store_true",
                        help="the one-env comparison instead of the headline: every method "
                        f"on --env (default {DEFAULT_ENV} in its default scene, Yu & Kim's "
                        "arena, homes anywhere); --env, --env-kwargs, --scene or "
                        "--success-on select it too")
    add_env_arguments(parser, DEFAULT_ENV)
    parser.set_defaults(env=None)        # given or not: it selects the one-env comparison
    parser.add_argument("--episodes", type=int, default=None,
                        help="episodes per setting of every protocol (default: the "
                        "headline's few, each protocol's own with --protocols); with "
                        "--arena per method (default 20)")
    parser.add_argument("--seed", type=seed_value, default=None,
                        help="the base seed of every protocol's episode draw instead of its "
                        "own (not the canonical draw: each cell's command then carries "
                        "--seed); with --arena the seed of the first episode (default 0)")
    parser.add_argument("--workers", type=worker_count, default=DEFAULT_WORKERS,
                        help=f"parallel processes (default {DEFAULT_WORKERS}: 2, or 1 on a "
                        "one-core machine)")
    parser.add_argument("--methods", nargs="+",
                        help="subset of methods (default: every classical method where it "
                        f"applies and the default learned policy, ppo = {DEFAULT_POLICY}; "
                        "with --arena or --protocols every shipped policy too)")
    parser.add_argument("--success-on", choices=("stop", "reach"), default=None,
                        help="the success rule of every row of the one-env comparison "
                        "(default stop): stopped at the goal, or came within its radius at "
                        "any time; the protocols' rule is stop")
    parser.add_argument("--out", default="results", type=output_dir_argument,
                        help="output folder (default: results)")
    parser.add_argument("--resume", action="store_true",
                        help="keep the episodes already streamed into --out (an interrupted "
                        "run, or one to which methods or protocols were added) and run only "
                        "the others; the cells of --out's matrix.json that this run does not "
                        "cover stay in it")
    add_backend_arguments(parser)
    args = parser.parse_args(argv)
    check_backend_arguments(parser, args)
    if args.methods:                                  # the alias of the default policy
        args.methods = list(dict.fromkeys(map(resolved_name, args.methods)))
    if args.episodes is not None and args.episodes < 1:
        parser.error("--episodes must be >= 1")
    one_env = [flag for flag, value in (("--env", args.env), ("--env-kwargs", args.env_kwargs),
                                        ("--scene", args.scene),
                                        ("--success-on", args.success_on)) if value]
    if args.protocols and (one_env or args.arena):
        parser.error(f"--protocols fix the envs and their kwargs; drop "
                     f"{'/'.join(one_env) or '--arena'}")
    try:
        with OutputLock(args.out):      # one run at a time in a folder
            if args.protocols:
                return _matrix(args)
            return _suite(args) if args.arena or one_env else _headline(args)
    except ValueError as err:
        parser.exit(2, f"homing-suite: error: {err}\n")
    except (WorkerDiedError, KeyboardInterrupt) as err:   # Ctrl-C, SIGTERM, SIGHUP too
        end_stopped_command(parser, err, f"the finished episodes are in the *.episodes.jsonl "
                                         f"files under {args.out}/: the same command with "
                                         f"--resume runs the rest")


def _matrix(args) -> int:
    """``--protocols``: run the matrix and print it."""
    names = sorted(PROTOCOLS) if args.protocols == ["all"] else args.protocols
    chosen = [protocol(name) for name in names]
    if args.seed is not None:
        chosen = [p.reseeded(args.seed) for p in chosen]
    cells = run_matrix(chosen, Path(args.out), args.episodes, args.workers, args.methods,
                       resume=args.resume, backend=args.backend, address=args.ray_address)
    print(matrix_markdown(cells))
    print(f"wrote {args.out}/matrix.md, matrix.csv, matrix.json, matrix.png")
    return 0


def _headline(args) -> int:
    """No ``--protocols`` or one-env option: the headline comparison, its table and
    reading."""
    plan = headline_plan(args.episodes, args.methods, args.seed)
    check_methods(plan)
    print("homing-suite: the headline comparison (--arena: the one-env comparison; "
          "--protocols all: every protocol at its own count)\n" + plan.describe())
    cells = run_matrix(plan.protocols, Path(args.out), plan.episodes, args.workers,
                       plan.methods, resume=args.resume, backend=args.backend,
                       address=args.ray_address, by_cell=True)
    print(f"wrote {args.out}/matrix.md (every cell's command, the papers' claims), "
          f"matrix.csv, matrix.json, matrix.png, and each cell's files under "
          f"{args.out}/<protocol>/<method>/\n")
    print(headline_table(cells))
    print(reading(cells), end="")
    return 0


def _suite(args) -> int:
    """``--arena`` or a one-env option: every method on one env, compared."""
    written = run_suite(Path(args.out), args.env or DEFAULT_ENV,
                        20 if args.episodes is None else args.episodes,
                        args.seed or 0, args.workers, args.methods, args.backend,
                        args.ray_address, args.success_on or "stop",
                        env_kwargs_from_args(args), resume=args.resume)
    print(Path(written["table"]).read_text())
    print("wrote " + ", ".join(written.values()))
    return 0


if __name__ == "__main__":
    sys.exit(main())
