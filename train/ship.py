"""Ship a trained run: copy its model into ``train/shipped/`` with its settings and curve.

    python -m train.ship runs/ppo_local --name ppo_local

writes ``train/shipped/<name>.zip`` (the run's ``best_model.zip``, chosen by the
evaluation on held-out training seeds, or ``model.zip`` with ``--final``),
``<name>.yml`` (the run's config, command, timesteps and wall time, and the
``eval_env_kwargs`` that ``homing-suite`` evaluates it with: the training env kwargs
without the training ``scene``, so the policy is scored in the env's default scene; and
``eval_params``: ``deterministic``, false with ``--stochastic``) and
``<name>_curve.png`` (the run's learning curve).
"""

from __future__ import annotations

import argparse
import json
import shutil
from pathlib import Path

import yaml

from train.suite import POLICY_DIR

MAX_BYTES = 10 * 2**20


class _PlainDumper(yaml.SafeDumper):
    """Writes repeated values in full instead of as YAML anchors and aliases."""

    def ignore_aliases(self, data) -> bool:
        return True


def ship_run(run: Path, name: str, folder: Path = POLICY_DIR, final: bool = False,
             stochastic: bool = False) -> Path:
    """Copy run ``run`` into ``folder`` as ``name``; returns the shipped zip's path.
    ``stochastic``: evaluate it by sampling actions (``eval_params: {deterministic:
    false}``) instead of taking the distribution's mode."""
    model = run / ("model.zip" if final else "best_model.zip")
    for needed in (model, run / "config.yml", run / "summary.json", run / "learning_curve.png"):
        if not needed.is_file():
            raise ValueError(f"{run} is not a finished run folder: {needed.name} is missing")
    if model.stat().st_size > MAX_BYTES:
        raise ValueError(f"{model} is {model.stat().st_size / 2**20:.1f} MiB; shipped policies "
                         f"must stay under {MAX_BYTES / 2**20:.0f} MiB")
    config = yaml.safe_load((run / "config.yml").read_text())
    summary = json.loads((run / "summary.json").read_text())
    eval_env_kwargs = {k: v for k, v in config["env_kwargs"].items() if k != "scene"}
    meta = {
        "env_id": config["env_id"],
        "eval_env_kwargs": eval_env_kwargs,
        "eval_params": {"deterministic": not stochastic},
        "model": "final model" if final else "best model on held-out training seeds",
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
    shutil.copyfile(model, target)
    (folder / f"{name}.yml").write_text(yaml.dump(meta, Dumper=_PlainDumper, sort_keys=False))
    shutil.copyfile(run / "learning_curve.png", folder / f"{name}_curve.png")
    return target


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m train.ship", description=__doc__.split("\n")[0])
    parser.add_argument("run", type=Path, help="run folder written by homing-train")
    parser.add_argument("--name", required=True, help="name of the shipped policy")
    parser.add_argument("--final", action="store_true",
                        help="ship model.zip instead of best_model.zip")
    parser.add_argument("--stochastic", action="store_true",
                        help="evaluate the shipped policy with sampled actions")
    args = parser.parse_args(argv)
    try:
        target = ship_run(args.run, args.name, final=args.final, stochastic=args.stochastic)
    except ValueError as err:
        parser.exit(2, f"ship: error: {err}\n")
    print(f"shipped {target}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
