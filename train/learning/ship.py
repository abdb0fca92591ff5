"""Ship a trained run: copy its model into ``train/shipped/`` with its settings and curve.

    python -m homing_train.learning.ship runs/ppo_local --name ppo_local [--model best|final|pretrain|imitation]

writes ``train/shipped/<name>.zip`` (by default the run's ``best_model.zip``, chosen by
the evaluation callback on held-out training seeds; ``--model final|pretrain|imitation``
ships ``model.zip`` or the network as the warm start left it),
``<name>.yml`` (the run's config, command, timesteps and wall time, and the
``eval_env_kwargs`` that ``homing-suite`` evaluates it with: the training env kwargs
without the training ``scene``, so the policy is scored in the env's default scene; and
``eval_params``: ``deterministic``, false with ``--stochastic``; ``privileged``: what
beyond pixels the training used, ``--privileged`` or derived from the run's warm starts,
named beside the policy in the methods x protocols matrix) and
``<name>_curve.png`` (the run's learning curve).
"""

from __future__ import annotations

import json
import shutil
import sys
from pathlib import Path

import yaml

from homing_gym.cli import command_parser
from homing_train.harness.policies import POLICY_DIR, eval_env_kwargs, privileged_training

MAX_BYTES = 10 * 2**20
#: ``--model`` choices: the run folder's model files.
MODELS = {"best": "best_model.zip", "final": "model.zip", "pretrain": "pretrain_model.zip",
          "imitation": "imitation_model.zip"}


class _PlainDumper(yaml.SafeDumper):
    """Writes repeated values in full instead of as YAML anchors and aliases."""

    def ignore_aliases(self, data) -> bool:
        return True


def ship_run(run: Path, name: str, folder: Path = POLICY_DIR, model: str = "best",
             stochastic: bool = False, why: str | None = None,
             privileged: str | None = None) -> Path:
    """Copy ``model`` (a key of :data:`MODELS`) of run ``run`` into ``folder`` as ``name``;
    returns the shipped zip's path. ``stochastic``: evaluate it by sampling actions
    (``eval_params: {deterministic: false}``) instead of taking the distribution's mode.
    ``why``: how the model was chosen, recorded in the ``.yml``; ``privileged``: what
    beyond pixels the training used (default: :func:`privileged_training` of the run's
    config, e.g. the oracle's demonstrations of a warm start)."""
    if model not in MODELS:
        raise ValueError(f"unknown model {model!r}; allowed: {list(MODELS)}")
    path = run / MODELS[model]
    for needed in (path, run / "config.yml", run / "summary.json", run / "learning_curve.png"):
        if not needed.is_file():
            raise ValueError(f"{run} is not a finished run folder: {needed.name} is missing")
    if path.stat().st_size > MAX_BYTES:
        raise ValueError(f"{path} is {path.stat().st_size / 2**20:.1f} MiB; shipped policies "
                         f"must stay under {MAX_BYTES / 2**20:.0f} MiB")
    config = yaml.safe_load((run / "config.yml").read_text())
    summary = json.loads((run / "summary.json").read_text())
    meta = {
        "env_id": config["env_id"],
        "eval_env_kwargs": eval_env_kwargs(config["env_kwargs"]),
        "eval_params": {"deterministic": not stochastic},
        "privileged": privileged_training(config) if privileged is None else privileged,
        "model": MODELS[model],
        "chosen": why or ("best evaluation-callback return on held-out training seeds"
                          if model == "best" else f"the run's {MODELS[model]}"),
        "commands": (run / "command.txt").read_text().splitlines()
        if (run / "command.txt").is_file() else [],
        "timesteps": summary["timesteps"],
        "wall_time_s": summary["wall_time_s"],
        "env_steps_per_s": summary["env_steps_per_s"],
        "config": config,
    }
    for warm_start in ("pretrain", "imitation"):
        record = run / f"{warm_start}.json"
        if record.is_file():
            meta[warm_start] = json.loads(record.read_text())
    folder.mkdir(parents=True, exist_ok=True)
    target = folder / f"{name}.zip"
    shutil.copyfile(path, target)
    (folder / f"{name}.yml").write_text(yaml.dump(meta, Dumper=_PlainDumper, sort_keys=False))
    shutil.copyfile(run / "learning_curve.png", folder / f"{name}_curve.png")
    return target


def main(argv: list[str] | None = None) -> int:
    parser = command_parser("python -m homing_train.learning.ship", __doc__)
    parser.add_argument("run", type=Path, help="run folder written by homing-train")
    parser.add_argument("--name", required=True, help="name of the shipped policy")
    parser.add_argument("--model", choices=list(MODELS), default="best",
                        help="which model of the run to ship (default: best)")
    parser.add_argument("--why", help="how the model was chosen (recorded in the .yml)")
    parser.add_argument("--stochastic", action="store_true",
                        help="evaluate the shipped policy with sampled actions")
    parser.add_argument("--privileged",
                        help="what beyond pixels the training used (default: the oracle's "
                             "demonstrations if the run had a warm start, else none)")
    args = parser.parse_args(argv)
    try:
        target = ship_run(args.run, args.name, model=args.model, stochastic=args.stochastic,
                          why=args.why, privileged=args.privileged)
    except ValueError as err:
        parser.exit(2, f"ship: error: {err}\n")
    print(f"shipped {target}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
