"""Success against training steps, on the training worlds and on worlds the policy never
saw: every saved checkpoint of ``homing-train`` runs scored on a protocol.

``python -m homing_train.figures.checkpoints runs/A runs/B --protocol unseen --episodes 5 --every 50000 4096 --out docs/generalisation``

scores ``RUN/checkpoints/ppo_<steps>_steps.zip`` (every ``--every`` steps; one value per run, or one for all;
``--since STEPS``: only those at ``STEPS`` or later), the
final ``RUN/model.zip`` and, where the run has one and ``--since`` is 0, ``RUN/pretrain_model.zip`` (the warm
start, drawn before step 0) on
``--protocol`` with ``--episodes`` per setting, each with the settings recorded in the run
(:func:`homing_train.harness.policies.recorded_settings`), the harness's stop rule and
deterministic actions unless the run evaluated stochastically, in ``--workers`` processes. Each checkpoint's cell is
kept in ``RUN/checkpoint_cells/<protocol>/<steps>/``, so an interrupted command resumes.
Writes ``checkpoints_<protocol>.png`` (one panel per run: success % with Wilson 95 %
intervals against env steps; dashed: the run's own evaluations on held-out *training*
seeds from ``evaluations.npz``) and ``checkpoints_<protocol>.md`` (the table, with each
setting's success where the protocol has several).
"""

from __future__ import annotations

import json
import re
import sys
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from homing_gym.cli import command_parser
from homing_train.harness.matrix import run_cell
from homing_train.harness.protocols import PROTOCOLS, protocol
from homing_gym.outputs import output_dir_argument, save_figure

_CHECKPOINT = re.compile(r"ppo_(\d+)_steps\.zip$")
#: Plot position (env steps) of a run's warm start, drawn before its first PPO step.
PRETRAIN_STEP = -1
#: Line colours of the runs, in order (Okabe & Ito).
RUN_COLOURS = ("#D55E00", "#009E73", "#0072B2", "#E69F00", "#CC79A7", "#56B4E9")


@dataclass(frozen=True)
class CheckpointScore:
    """One checkpoint's cell: env steps (``PRETRAIN_STEP`` for the warm start), episodes,
    successes under the stop rule, the Wilson 95 % interval, the command and each
    setting's success rate (label -> fraction)."""

    steps: int
    episodes: int
    successes: int
    ci: tuple[float, float]
    command: str
    per_setting: dict[str, float] = field(default_factory=dict)


def run_checkpoints(run: Path, every: int, since: int = 0) -> list[tuple[int, Path]]:
    """``(steps, zip)`` of the run's warm start (if any, and ``since`` is 0), of its
    checkpoints spaced by ``every`` steps (the first at ``every`` or later, then each at
    least ``every`` past the last one taken: the multiples of ``every`` where the run
    saved them, and still evenly spread after a resume shifted its checkpoints) and of
    its final ``model.zip`` (at the steps in ``summary.json``, where the run finished),
    in step order; only those at ``since`` steps or later."""
    if since < 0:
        raise ValueError(f"since must be >= 0 env steps, got {since}")
    found = sorted((int(m.group(1)), p) for p in (run / "checkpoints").glob("ppo_*_steps.zip")
                   if (m := _CHECKPOINT.search(p.name)))
    chosen: list[tuple[int, Path]] = []
    for steps, path in found:
        if steps - (chosen[-1][0] if chosen else 0) >= every:
            chosen.append((steps, path))
    final = _final_steps(run)
    if final is not None and (run / "model.zip").is_file() and all(s != final for s, _ in chosen):
        chosen.append((final, run / "model.zip"))
    if (run / "pretrain_model.zip").is_file():
        chosen.insert(0, (PRETRAIN_STEP, run / "pretrain_model.zip"))
    chosen = [(s, p) for s, p in chosen if s >= since or (since == 0 and s == PRETRAIN_STEP)]
    if not chosen:
        raise ValueError(f"{run} has no checkpoints at {max(every, since)} steps or later "
                         f"(found {[s for s, _ in found]}) and no pretrain_model.zip")
    return chosen


def _final_steps(run: Path) -> int | None:
    """Env steps of the run's final model, from ``summary.json`` (None without one)."""
    path = run / "summary.json"
    return json.loads(path.read_text()).get("timesteps") if path.is_file() else None


def score_run(run: Path, protocol_name: str, episodes: int, every: int,
              progress: bool = True, since: int = 0, workers: int = 1) -> list[CheckpointScore]:
    """Every chosen checkpoint of ``run`` scored on the protocol (resuming kept cells)."""
    chosen_protocol = protocol(protocol_name)
    scores = []
    for steps, model in run_checkpoints(run, every, since):
        out = run / "checkpoint_cells" / protocol_name / str(steps)
        cell = run_cell(chosen_protocol, str(model), out, episodes=episodes,
                        workers=workers, progress=progress, resume=True)
        n = cell.summary["episodes"]
        per_setting = ({label: s["success_rate"] for label, s in cell.settings.items()}
                       if len(cell.settings) > 1 else {})
        scores.append(CheckpointScore(steps, n, round(cell.summary["success_rate"] * n),
                                      tuple(cell.summary["success_ci"]), cell.command,
                                      per_setting))
    return scores


def training_evaluations(run: Path) -> tuple[np.ndarray, np.ndarray]:
    """Steps and success rates of the run's evaluation callback (empty without one)."""
    path = run / "evaluations.npz"
    if not path.is_file():
        return np.zeros(0), np.zeros(0)
    data = np.load(path)
    if "successes" not in data or data["successes"].size == 0:
        return np.zeros(0), np.zeros(0)
    return data["timesteps"], data["successes"].mean(axis=1)


def markdown(results: dict[str, list[CheckpointScore]], protocol_name: str) -> str:
    """One row per run and checkpoint: success % [Wilson 95 % CI] (k/n), after each
    setting's success % where the scores have them."""
    labels = list(dict.fromkeys(k for scores in results.values() for s in scores
                                for k in s.per_setting))
    rows = [f"| run | env steps | {''.join(f'{k} | ' for k in labels)}"
            f"{protocol_name}: success % [95% CI] | episodes |",
            "|---|---:|" + "---:|" * len(labels) + "---:|---:|"]
    for run, scores in results.items():
        for s in scores:
            steps = "warm start" if s.steps == PRETRAIN_STEP else f"{s.steps:,}"
            settings = "".join(f"{100 * s.per_setting[k]:.0f} | " if k in s.per_setting
                               else "- | " for k in labels)
            rows.append(f"| {run} | {steps} | {settings}{100 * s.successes / s.episodes:.0f} "
                        f"[{100 * s.ci[0]:.0f}, {100 * s.ci[1]:.0f}] | "
                        f"{s.successes}/{s.episodes} |")
    return "\n".join(rows) + "\n"


def plot(results: dict[str, list[CheckpointScore]], runs: dict[str, Path],
         protocol_name: str, path: Path) -> None:
    """One panel per run: success against env steps on the protocol (solid, with
    intervals) and on the run's held-out training seeds (dashed)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.ticker import FuncFormatter

    fig, axes = plt.subplots(1, len(results), figsize=(4.2 * len(results), 3.6), dpi=150,
                             sharey=True, squeeze=False)
    for ax, (name, scores), colour in zip(axes[0], results.items(), RUN_COLOURS):
        steps = np.array([max(s.steps, 0) for s in scores])
        rate = np.array([100 * s.successes / s.episodes for s in scores])
        low = rate - np.array([100 * s.ci[0] for s in scores])
        high = np.array([100 * s.ci[1] for s in scores]) - rate
        ax.errorbar(steps, rate, yerr=[low, high], color=colour, marker="o", ms=4,
                    capsize=2, label=f"{protocol_name} ({scores[0].episodes} episodes each)")
        if scores[0].steps == PRETRAIN_STEP:
            ax.annotate("warm start", (0, rate[0]), textcoords="offset points",
                        xytext=(4, -12), fontsize=7, color=colour)
        train_steps, train_rate = training_evaluations(runs[name])
        if len(train_steps):
            ax.plot(train_steps, 100 * train_rate, color=colour, ls="--", lw=1,
                    label="training worlds, held-out seeds")
        ax.set_title(name, fontsize=9)
        ax.set_xlabel("environment steps of PPO")
        ax.xaxis.set_major_formatter(FuncFormatter(lambda x, _: f"{x / 1000:g}k" if x else "0"))
        ax.set_ylim(-2, 102)
        ax.legend(fontsize=7, loc="upper right")
    axes[0][0].set_ylabel("success % (stopped within radius)")
    fig.suptitle(f"success against training steps (Wilson 95% intervals on {protocol_name})",
                 fontsize=9)
    fig.tight_layout()
    save_figure(fig, path)
    plt.close(fig)


def main(argv: list[str] | None = None) -> int:
    parser = command_parser("python -m homing_train.figures.checkpoints", __doc__)
    parser.add_argument("runs", nargs="+", type=Path, help="homing-train run folders")
    parser.add_argument("--protocol", default="unseen", choices=sorted(PROTOCOLS))
    parser.add_argument("--episodes", type=int, default=5, help="episodes per setting")
    parser.add_argument("--every", type=int, nargs="+", default=[50000],
                        help="score checkpoints this many steps apart (one value for "
                             "every run, or one per run)")
    parser.add_argument("--since", type=int, default=0,
                        help="only checkpoints at this many env steps or later")
    parser.add_argument("--workers", type=int, default=1, help="parallel processes")
    parser.add_argument("--out", type=output_dir_argument, default="docs/generalisation")
    parser.add_argument("--no-progress", action="store_true")
    args = parser.parse_args(argv)
    if len(args.every) == 1:
        args.every *= len(args.runs)
    if (args.episodes < 1 or min(args.every) < 1 or len(args.every) != len(args.runs)
            or args.since < 0 or args.workers < 1):
        parser.error(f"--episodes, --every and --workers must be >= 1, --since >= 0, and "
                     f"--every one value or one per run; got --episodes {args.episodes}, "
                     f"--every {args.every} for {len(args.runs)} runs, --since {args.since}, "
                     f"--workers {args.workers}")
    runs = {run.name: run for run in args.runs}
    try:
        results = {name: score_run(run, args.protocol, args.episodes, every,
                                   not args.no_progress, args.since, args.workers)
                   for (name, run), every in zip(runs.items(), args.every)}
    except ValueError as err:
        parser.exit(2, f"checkpoints: error: {err}\n")
    args.out = Path(args.out)
    args.out.mkdir(parents=True, exist_ok=True)
    table = markdown(results, args.protocol)
    (args.out / f"checkpoints_{args.protocol}.md").write_text(table)
    plot(results, runs, args.protocol, args.out / f"checkpoints_{args.protocol}.png")
    print(table)
    print(f"wrote {args.out}/checkpoints_{args.protocol}.md and .png")
    return 0


if __name__ == "__main__":
    sys.exit(main())
