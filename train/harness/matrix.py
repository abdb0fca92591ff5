"""Running protocols (:mod:`homing_train.harness.protocols`): one method on one protocol
(a *cell*), and the methods x protocols matrix.

A cell runs the method on every setting of the protocol with :func:`evaluate` (episodes
streamed to ``<setting>.episodes.jsonl``, so an interrupted run resumes), writes each
setting's result JSON and ``cell.json`` (the summary over all its episodes, per-setting
success and the command that reproduces it). The matrix writes ``matrix.md``,
``matrix.csv``, ``matrix.json`` and ``matrix.png`` (a heat map of success); ``matrix.md``
ends with the papers' claims beside our cells (:func:`claims_markdown`) and each method's
success aggregated over ``local-common`` and ``unseen`` with stratified-bootstrap
intervals (:func:`aggregate_markdown`).

Shipped policies, and PPO model zips given by path (``homing-eval --protocol unseen
--policy runs/RUN/best_model.zip``), are run with the settings recorded beside them
(their ``.yml``, or their run folder's ``config.yml``: panorama size, action type, control
period); where a protocol caps the episode length
(``max_episode_steps``, counted in steps of the default 0.1 s control period) a policy with
another control period gets the same time, not the same number of steps.

``python -m homing_train.harness.matrix docs/matrix/matrix.json`` writes the README's
matrix block (between its two marker lines) and the ``matrix.md`` beside it from a
matrix.json; with ``--merge NEW.json``
(repeatable) the cells of newer runs (``homing-suite --protocols ... --methods ...``) first
replace the same protocol and method's cells in it, and its matrix files are rewritten.
"""

from __future__ import annotations

import contextlib
import csv
import json
import re
import sys
import time
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Callable, Mapping, Sequence

import gymnasium as gym
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import homing_baselines  # noqa: E402
from homing_gym.cli import command_parser  # noqa: E402
from homing_train.extras import missing_extra  # noqa: E402
from homing_train.harness.evaluate import EpisodeRecord, evaluate, summarize  # noqa: E402
from homing_train.harness.policies import (model_zips, resolved_name,  # noqa: E402
                                           shipped_policies)
from homing_train.harness.metrics import aggregate_success, wilson_interval  # noqa: E402
from homing_train.harness.protocols import (POLICIES, PROTOCOLS, Protocol,  # noqa: E402
                                            episodes_key)
from homing_gym.outputs import save_figure, write_text_atomic  # noqa: E402
from homing_train.pool import pool_results  # noqa: E402

#: The control period (s) that protocols count ``max_episode_steps`` in.
BASE_PERIOD = 0.1


@dataclass
class Cell:
    """One method on one protocol: the summary over all its episodes (success under
    the stop rule, ``reached_rate``, SPL, ... with 95% CIs), per-setting success and
    episode counts, and the command that reproduces it; ``privileged``: what beyond
    pixels the protocol gives and the policy trained on (its shipped ``.yml``);
    ``seed``: the base seed its episodes were drawn from, ``canonical_draw``: whether
    that is the protocol's own (``homing-eval --protocol P --seed S`` draws others);
    ``success_on``: the success rule its episodes were scored under."""

    protocol: str
    version: int
    method: str
    command: str
    summary: dict
    settings: dict
    privileged: str = ""
    seed: int | None = None
    canonical_draw: bool = True
    success_on: str = "stop"


def shipped_for(env_ids: Sequence[str]) -> dict:
    """Shipped PPO policies trained on one of ``env_ids`` (none without the train extra)."""
    if missing_extra("train"):
        return {}
    return {name: p for name, p in shipped_policies().items() if p.env_id in env_ids}


def protocol_policy_envs(protocol: Protocol) -> set[str]:
    """The env ids whose shipped policies act in ``protocol``: its settings' and its
    ``policy_envs``."""
    return {s.env_id for s in protocol.settings} | set(protocol.policy_envs)


def cell_methods(protocol: Protocol) -> list[str]:
    """The protocol's methods, ``policies`` replaced by the shipped policies trained on
    its envs."""
    names: list[str] = []
    for method in protocol.methods:
        if method == POLICIES:
            names += sorted(shipped_for(protocol_policy_envs(protocol)))
        else:
            names.append(method)
    return names


#: Settings a shipped policy keeps from its own record in every protocol.
POLICY_OWN = ("renderer", "physics_substeps", "supersampling")
#: What else a policy's record may bring where the setting is silent: the format of its
#: input and output, its control period (its step cap becomes the same time) and its
#: training reward (which decides no episode). Anything else it recorded (success
#: radius, start distances, speeds, stop threshold, lighting, noise, camera, odometry
#: frame, ...) would change the task, so it is the setting's, else the env's default.
POLICY_FORMAT = ("panorama_shape", "action_type", "control_period", "obs_keys", "reward",
                 "episodes_per_world")


def episode_seconds(env_id: str, env_kwargs: dict) -> float | None:
    """Simulated seconds an episode may last: its step cap (``env_kwargs``' or the env
    id's registered one) times its control period; ``None`` without a cap."""
    steps = env_kwargs.get("max_episode_steps", gym.spec(env_id).max_episode_steps)
    if steps is None or steps < 0:
        return None
    return steps * float(env_kwargs.get("control_period", BASE_PERIOD))


def equal_time_kwargs(setting_kwargs: dict, recorded: dict, default_steps: int | None) -> dict:
    """A shipped policy's recorded env kwargs under a setting's: the setting wins, except
    that the policy keeps its own renderer and physics (:data:`POLICY_OWN`: what it was
    trained with, until it is retrained), and every row gets the same time: the
    setting's step cap, or where it sets none the env id's registered one
    (``default_steps``; ``None``: no cap), counted at the setting's control period
    (:data:`BASE_PERIOD` unless it sets one), becomes the same time at the period the
    policy acts at. The cap the policy was trained with (in ``recorded``) is never used:
    it would give a policy more or less time than the controllers beside it."""
    merged = {**{key: recorded[key] for key in POLICY_FORMAT if key in recorded},
              **setting_kwargs,
              **{key: recorded[key] for key in POLICY_OWN if key in recorded}}
    steps = setting_kwargs.get("max_episode_steps", default_steps)
    merged.pop("max_episode_steps", None)
    if steps is not None:
        seconds = steps * float(setting_kwargs.get("control_period", BASE_PERIOD))
        period = float(merged.get("control_period", BASE_PERIOD))
        merged["max_episode_steps"] = max(1, round(seconds / period))
    return merged


def made_for_text(method: str) -> str:
    """Where ``method`` applies: a controller's envs and scenes
    (:meth:`homing_baselines.Controller.made_for`), a shipped policy's training env."""
    if method in homing_baselines.available():
        cls = homing_baselines.controller_class(method)
        parts = [f"envs {list(cls.envs)}" if cls.envs is not None else "",
                 f"scenes {list(cls.scenes)}" if cls.scenes is not None else ""]
        return "made for " + (" in ".join(p for p in parts if p) or "any env")
    shipped = shipped_policies().get(method)
    return (f"a policy trained on {shipped.env_id}" if shipped is not None
            else "not a controller or a shipped policy")


def applicable(methods: Sequence[str], allowed: set[str], where: Callable[[], str]
               ) -> list[str]:
    """The ``methods`` in ``allowed`` (those that can run ``where()``, e.g. "protocol
    yukim"), in order; the others are left out with a printed note saying why
    (:func:`made_for_text`), or, when none is left, ``ValueError`` saying it."""
    kept = [m for m in methods if m in allowed]
    left_out = [m for m in methods if m not in allowed]
    if left_out:
        why = "; ".join(f"{m}: {made_for_text(m)}" for m in left_out)
        if not kept:
            raise ValueError(f"{', '.join(left_out)} cannot run in {where()} ({why}); "
                             f"nothing left to run")
        print(f"note: left out {', '.join(left_out)}, which cannot run in {where()} ({why})")
    return kept


def setting_stem(label: str) -> str:
    """The file stem of a setting's results in a cell's folder (``hallway (held out)`` ->
    ``hallway_held_out``)."""
    return re.sub(r"[^a-z0-9]+", "_", label.lower()).strip("_")


def run_cell(protocol: Protocol, method: str, out: Path, episodes: int | None = None,
             workers: int = 1, progress: bool = True, resume: bool = False,
             backend: str = "local", address: str | None = None) -> Cell:
    """Run ``method`` (a controller name, a shipped policy's (``ppo``: the default one),
    or the path of a PPO model zip, evaluated with
    :func:`~homing_train.harness.policies.recorded_settings` as a shipped one is) on every setting of ``protocol`` (``episodes`` per setting, default
    the protocol's) into ``out`` (``backend``/``address``:
    :func:`homing_train.harness.evaluate.run_episodes`)."""
    method = resolved_name(method)
    n = protocol.episodes if episodes is None else episodes
    if n < 1:
        raise ValueError(f"episodes must be >= 1, got {n}")
    shipped = {**shipped_for(protocol_policy_envs(protocol)), **model_zips([method])}
    if method not in shipped and method not in homing_baselines.available():
        raise ValueError(f"unknown method {method!r} for protocol {protocol.name!r}; "
                         f"allowed: {cell_methods(protocol)} or a PPO model .zip")
    if method in homing_baselines.available() and method not in protocol.methods:
        made_for = homing_baselines.controller_class(method).made_for
        misfit = [f"{s.label!r} ({s.env_id}, scene {_scene(s)!r})" for s in protocol.settings
                  if not made_for(s.env_id, _scene(s))]
        if misfit:
            raise ValueError(f"{method} cannot run in protocol {protocol.name!r}: it is "
                             f"{made_for_text(method)}, and the protocol's settings "
                             f"{', '.join(misfit)} are not; its methods: "
                             f"{cell_methods(protocol)}")
    out.mkdir(parents=True, exist_ok=True)
    records: list[EpisodeRecord] = []
    per_setting = {}
    for setting in protocol.settings:
        kwargs = setting.kwargs()
        if method in shipped:
            policy, params = str(shipped[method].path), shipped[method].params
            kwargs = equal_time_kwargs(kwargs, shipped[method].env_kwargs,
                                       gym.spec(setting.env_id).max_episode_steps)
        else:
            policy, params = method, {}
        stem = out / setting_stem(setting.label)
        result = evaluate(policy, setting.env_id, env_kwargs=kwargs, workers=workers,
                          params=params, progress=progress,
                          stream=f"{stem}.episodes.jsonl", resume=resume,
                          tasks=setting.episode_tasks(n, protocol.seed), backend=backend,
                          address=address, use_record=False)    # equal_time_kwargs chose
        result.save(f"{stem}.json")
        records += result.episodes
        per_setting[setting.label] = {
            "episodes": len(result.episodes), "success_rate": result.summary["success_rate"],
            "reached_rate": result.summary["reached_rate"]}
    radius = protocol.success_radius(protocol.settings[0])
    own = shipped[method].privileged if method in shipped else ""
    cell = Cell(protocol=protocol.name, version=protocol.version, method=method,
                command=protocol.command(method, episodes),
                summary=summarize(records, radius=radius), settings=per_setting,
                privileged="; ".join(p for p in (protocol.privileged, own) if p),
                seed=protocol.seed, canonical_draw=protocol.canonical,
                success_on=protocol.settings[0].kwargs()["success_on"])
    write_text_atomic(str(out / "cell.json"), json.dumps(asdict(cell), indent=1))
    return cell


def _scene(setting) -> str | None:
    """The scene name a protocol's setting gives its env (``None``: the env's default)."""
    scene = setting.env_kwargs.get("scene")
    return getattr(scene, "name", scene)


def run_matrix(protocols: Sequence[Protocol], out: Path,
               episodes: int | Mapping[str, int] | None = None, workers: int = 1,
               methods: Sequence[str] | None = None, progress: bool = True,
               resume: bool = False, backend: str = "local", address: str | None = None,
               by_cell: bool = False) -> list[Cell]:
    """Every applicable method (or those of ``methods`` that apply) on every protocol;
    cells under ``out/<protocol>/<method>/``, the matrix files in ``out``; ``episodes``
    per setting: one count for all, or a count per protocol name (default: each
    protocol's own). With ``resume`` the cells of an earlier ``out/matrix.json`` that
    were not run again (other methods or protocols) stay in the matrix. Of ``methods``,
    those that apply to none of ``protocols`` are left out with a note (``ValueError`` if
    none is left). ``by_cell`` (local backend): ``workers`` processes run whole cells,
    each cell's episodes in one of them, a line printed as each cell ends (many small
    cells: no pool per setting)."""
    if methods:
        methods = applicable(list(methods), {m for p in protocols for m in cell_methods(p)},
                             lambda: "the protocols " + ", ".join(p.name for p in protocols))
    jobs = [(protocol, method, out / protocol.name / method,
             episodes.get(protocol.name) if isinstance(episodes, Mapping) else episodes,
             resume) for protocol in protocols for method in cell_methods(protocol)
            if not methods or method in methods]
    if by_cell and backend == "local" and workers > 1:
        cells = cells_in_parallel(jobs, workers)
    else:
        cells = [run_cell(protocol, method, path, n, workers, progress, again, backend,
                          address) for protocol, method, path, n, again in jobs]
    if resume and (out / "matrix.json").exists():
        cells = merged_cells(load_cells(out / "matrix.json"), cells)
    write_matrix(cells, out)
    return cells


def _timed_cell(job: tuple) -> tuple[Cell, float]:
    """A job of :func:`cells_in_parallel` run in this process: its cell and wall seconds."""
    protocol, method, path, episodes, resume = job
    start = time.perf_counter()
    cell = run_cell(protocol, method, path, episodes, 1, progress=False, resume=resume)
    return cell, time.perf_counter() - start


def job_cost(job: tuple) -> int:
    """A cell job's most env steps: its episodes times their step cap (what a method that
    never stops, e.g. ``random``, runs)."""
    protocol, _, _, episodes, _ = job
    n = protocol.episodes if episodes is None else episodes
    return sum(len(s.episode_tasks(n, protocol.seed))
               * (s.env_kwargs.get("max_episode_steps")
                  or gym.spec(s.env_id).max_episode_steps or 1)
               for s in protocol.settings)


def cells_in_parallel(jobs: Sequence[tuple], workers: int) -> list[Cell]:
    """The cells of ``jobs`` (protocol, method, folder, episodes, resume), run by
    ``workers`` processes, the costliest first (:func:`job_cost`), in ``jobs``' order;
    one line per cell as it ends, and the sum of the cells' wall times."""
    order = sorted(range(len(jobs)), key=lambda i: -job_cost(jobs[i]))
    cells: dict[int, Cell] = {}
    total = 0.0
    with contextlib.closing(pool_results(_timed_cell, [jobs[i] for i in order], workers,
                                         name=lambda job: f"{job[0].name} x {job[1]}")) as done:
        for index, (cell, seconds) in done:
            cells[order[index]] = cell
            total += seconds
            k = round(cell.summary["success_rate"] * cell.summary["episodes"])
            print(f"[{len(cells)}/{len(jobs)}] {cell.protocol} x {cell.method}: "
                  f"{k}/{cell.summary['episodes']} stopped at the goal ({seconds:.0f} s)",
                  flush=True)
    print(f"{len(jobs)} cells, {total:.0f} s of cell time in all ({workers} processes)")
    return [cells[i] for i in range(len(jobs))]


def load_cells(path: str | Path) -> list[Cell]:
    """The cells of a ``matrix.json``."""
    try:
        docs = json.loads(Path(path).read_text())
        return [Cell(**d) for d in docs]
    except (OSError, json.JSONDecodeError, TypeError) as err:
        raise ValueError(f"{path}: not a matrix.json of homing-suite --protocols ({err})") \
            from None


def merged_cells(cells: Sequence[Cell], newer: Sequence[Cell]) -> list[Cell]:
    """``cells`` with each cell of ``newer`` in place of the one of the same protocol and
    method (appended where there is none), in ``cells``' order."""
    fresh = {(c.protocol, c.method): c for c in newer}
    out = [fresh.pop((c.protocol, c.method), c) for c in cells]
    return out + list(fresh.values())


#: The README lines between which :func:`update_readme` writes the success table.
README_BEGIN = "<!-- matrix: generated by python -m homing_train.harness.matrix, do not edit -->"
README_END = "<!-- matrix end -->"


def readme_block(cells: Sequence[Cell], source: str) -> str:
    """The README's matrix: the success table of :func:`matrix_markdown` with its notes
    and where the cells come from (``source``: the matrix.json) and how they were made."""
    blocks = matrix_markdown(cells).split("\n\n")
    table = "\n\n".join(blocks[:next(i for i, b in enumerate(blocks)
                                    if b.startswith("| protocol | method"))])
    episodes = sorted({c.summary["episodes"] for c in cells})
    return (f"{README_BEGIN}\n{table}\n\n*{len(cells)} cells, {episodes[0]}-{episodes[-1]} "
            f"episodes each, from [{source}]({source}); every cell's command, reached "
            f"rate, SPL and final distance: [{Path(source).with_suffix('.md')}]"
            f"({Path(source).with_suffix('.md')}).*\n{README_END}")


def update_readme(readme: str | Path, matrix_json: str | Path) -> None:
    """Rewrite the block between :data:`README_BEGIN` and :data:`README_END` of ``readme``
    from ``matrix_json`` (a path relative to the README)."""
    text = Path(readme).read_text()
    if README_BEGIN not in text or README_END not in text:
        raise ValueError(f"{readme} has no matrix block ({README_BEGIN!r} ... {README_END!r})")
    head, rest = text.split(README_BEGIN, 1)
    tail = rest.split(README_END, 1)[1]
    block = readme_block(load_cells(Path(readme).parent / matrix_json), str(matrix_json))
    Path(readme).write_text(head + block + tail)


def _pct(summary: dict, key: str, ci: str) -> str:
    lo, hi = summary[ci]
    return f"{100 * summary[key]:.0f} [{100 * lo:.0f}, {100 * hi:.0f}]"


def matrix_markdown(cells: Sequence[Cell]) -> str:
    """Success % [95% Wilson CI] by method and protocol (a method whose cells used
    privileged data is named with it), then one row per cell with the other metrics and
    the command that reproduces it."""
    protocols = list(dict.fromkeys(c.protocol for c in cells))
    methods = list(dict.fromkeys(c.method for c in cells))
    by = {(c.protocol, c.method): c for c in cells}
    redrawn = sorted({f"{c.protocol} (seed {c.seed})" for c in cells if not c.canonical_draw})
    privileged = {m: "; ".join(dict.fromkeys(
        p for p in [c.privileged for c in cells if c.method == m]
        + ([homing_baselines.controller_class(m).privileged]
           if m in homing_baselines.available() else []) if p))
        for m in methods}
    lines = ["Success: the agent stopped within the success radius of the goal (0.15 m; "
             "0.10 m in shiraishi-house; in briggs-corridors: stopped in front of the goal "
             "landmark); % with 95% Wilson interval, episodes per cell in the second table.",
             *([f"Not the canonical draw of episodes: {', '.join(redrawn)}.", ""]
               if redrawn else [""]),
             "| method | " + " | ".join(protocols) + " |",
             "|---|" + "---:|" * len(protocols)]
    no_policy = {p: PROTOCOLS[p].no_policy for p in protocols
                 if p in PROTOCOLS and PROTOCOLS[p].no_policy}
    for m in methods:
        learned = m not in homing_baselines.available()
        row = [(_pct(by[(p, m)].summary, "success_rate", "success_ci") if (p, m) in by
                else "n/a" if learned and p in no_policy else "") for p in protocols]
        label = f"{m} (privileged: {privileged[m]})" if privileged[m] else m
        lines.append(f"| {label} | " + " | ".join(row) + " |")
    if no_policy and any(m not in homing_baselines.available() for m in methods):
        lines += ["", "n/a: no learned policy can act here. " + " ".join(
            f"{p}: {why}." for p, why in no_policy.items())]
    lines += ["", "| protocol | method | episodes | success % [95% CI] | reached % [95% CI] "
              "| SPL | final distance (cm) | command |", "|---|---|---:|---:|---:|---:|---:|---|"]
    for c in cells:
        s = c.summary
        radial = not (c.protocol in PROTOCOLS and PROTOCOLS[c.protocol].place)
        lines.append(f"| {c.protocol} v{c.version} | {c.method} | {s['episodes']} | "
                     f"{_pct(s, 'success_rate', 'success_ci')} | "
                     f"{_pct(s, 'reached_rate', 'reached_ci') if radial else '-'} | "
                     f"{s['spl']:.2f} | "
                     f"{100 * s['final_distance_mean']:.0f} | `{c.command}` |")
    return "\n".join(lines) + "\n\n" + claims_markdown(cells) + "\n" + aggregate_markdown(cells)


def _k_of_n(rate: float, n: int) -> str:
    return f"{round(rate * n)}/{n}"


def claims_markdown(cells: Sequence[Cell]) -> str:
    """One row per paper claim (:class:`~homing_train.harness.protocols.Claim`) of the
    protocols in ``cells``: the paper's claim, its numbers and where, its runs with their
    Wilson interval where it gives them, our success and reached (k/n, Wilson) in the
    protocol, and how the protocol differs from the paper's setting."""
    by = {(c.protocol, c.method): c for c in cells}
    lines = ["### The papers' claims beside ours", "",
             "The paper's claim as it states it (quoted where in quotes) and the numbers it "
             "prints; \"paper: reached\" counts the paper's own runs that reached the goal "
             "(95% Wilson interval) where its figures give them. Ours: the protocol's cell "
             "above (success: stopped at the goal).", "",
             "| protocol | method | paper | paper's claim | paper's numbers | paper: reached "
             "| ours: success % [95% CI] | ours: reached % [95% CI] | how ours differs |",
             "|---|---|---|---|---|---:|---:|---:|---|"]
    for protocol in PROTOCOLS.values():
        if not any(c.protocol == protocol.name for c in cells):
            continue
        for claim in protocol.claims:
            paper = "-"
            if claim.runs is not None:
                k, n = claim.runs
                lo, hi = wilson_interval(k, n)
                paper = f"{k}/{n} = {100 * k / n:.0f}% [{100 * lo:.0f}, {100 * hi:.0f}]"
            cell = by.get((protocol.name, claim.method))
            if cell is None:
                ours = reached = "not run"
            else:
                s, n = cell.summary, cell.summary["episodes"]
                ours = f"{_pct(s, 'success_rate', 'success_ci')} ({_k_of_n(s['success_rate'], n)})"
                reached = ("-" if protocol.place else
                           f"{_pct(s, 'reached_rate', 'reached_ci')} "
                           f"({_k_of_n(s['reached_rate'], n)})")
            lines.append(f"| {protocol.label} | {claim.method} | {claim.where} | {claim.text} "
                         f"| {claim.numbers or '-'} | {paper} | {ours} | {reached} "
                         f"| {claim.differs} |")
    return "\n".join(lines) + "\n"


#: The protocols aggregated across (:func:`aggregate_markdown`): the two suites that every
#: homing method and every shipped policy runs, in the same version, renderer and physics.
AGGREGATE_PROTOCOLS = ("local-common", "unseen")


def _episodes_key(cell: Cell, label: str) -> tuple:
    """:func:`~homing_train.harness.protocols.episodes_key` of the cell's setting
    ``label``; the cell's own (protocol, version, label) where the protocol or its
    version is not defined here."""
    protocol = PROTOCOLS.get(cell.protocol)
    if protocol is not None and protocol.version == cell.version:
        for setting in protocol.settings:
            if setting.label == label:
                return episodes_key(protocol, setting)
    return (cell.protocol, cell.version, label)


def strata_counts(cells: Sequence[Cell], protocols: Sequence[str] = AGGREGATE_PROTOCOLS
                  ) -> dict[str, list[tuple[int, int]]]:
    """(successes, episodes) per distinct setting of ``protocols`` (a setting two of them
    share counts once, with the first one's episodes), for each method that has a cell in
    every one of ``protocols``."""
    by = {(c.protocol, c.method): c for c in cells}
    methods = [m for m in dict.fromkeys(c.method for c in cells)
               if all((p, m) in by for p in protocols)]
    out = {}
    for m in methods:
        strata: dict[tuple, tuple[int, int]] = {}
        for p in protocols:
            cell = by[(p, m)]
            for label, setting in cell.settings.items():
                n = int(setting["episodes"])
                strata.setdefault(_episodes_key(cell, label),
                                  (round(setting["success_rate"] * n), n))
        out[m] = list(strata.values())
    return out


def aggregate_markdown(cells: Sequence[Cell],
                       protocols: Sequence[str] = AGGREGATE_PROTOCOLS) -> str:
    """Success of each method over the distinct settings (worlds) of ``protocols``: mean
    and IQM of the per-setting rates with the stratified-bootstrap interval of
    :func:`~homing_train.harness.metrics.aggregate_success`."""
    counts = strata_counts(cells, protocols)
    names = " and ".join(protocols)
    lines = [f"### Aggregate over {names}", "",
             f"Success of each method that ran in all of {names}, over their distinct "
             "settings (worlds; a setting that two of them share, the same env kwargs and "
             "seeds, counts once): mean and interquartile mean (IQM, 25% trimmed) of the "
             "per-setting success rates, every setting weighing alike, % with 95% "
             "percentile intervals of the stratified bootstrap (episodes resampled within "
             "each setting from its k/n, 10,000 resamples, seed 0). A method at 0% or "
             "100% everywhere gets a zero-width interval.", "",
             "| method | settings | episodes | mean success % [95% CI] | IQM % [95% CI] |",
             "|---|---:|---:|---:|---:|"]
    for method, strata in counts.items():
        a = asdict(aggregate_success(strata))
        lines.append(f"| {method} | {a['strata']} | {a['episodes']} | "
                     f"{_pct(a, 'mean', 'mean_ci')} | {_pct(a, 'iqm', 'iqm_ci')} |")
    if not counts:
        lines.append("| (no method ran in all of them) | | | | |")
    return "\n".join(lines) + "\n"


def plot_matrix(cells: Sequence[Cell], path: str) -> None:
    """Heat map of success % (methods x protocols) with k/n in each cell."""
    protocols = list(dict.fromkeys(c.protocol for c in cells))
    methods = list(dict.fromkeys(c.method for c in cells))
    grid = np.full((len(methods), len(protocols)), np.nan)
    fig, ax = plt.subplots(figsize=(1.6 + 1.3 * len(protocols), 0.9 + 0.45 * len(methods)),
                           dpi=110)
    for c in cells:
        i, j = methods.index(c.method), protocols.index(c.protocol)
        grid[i, j] = 100 * c.summary["success_rate"]
        k = round(c.summary["success_rate"] * c.summary["episodes"])
        ax.text(j, i, f"{grid[i, j]:.0f}%\n{k}/{c.summary['episodes']}", ha="center",
                va="center", fontsize=7, color="black" if grid[i, j] > 45 else "white")
    image = ax.imshow(grid, cmap="viridis", vmin=0, vmax=100, aspect="auto")
    ax.set_xticks(range(len(protocols)), protocols, rotation=30, ha="right", fontsize=8)
    ax.set_yticks(range(len(methods)), methods, fontsize=8)
    ax.set_title("success % (stopped at the goal: within 0.15 m, see matrix.md); k/n "
                 "episodes; blank: not applicable", fontsize=8)
    fig.colorbar(image, ax=ax, label="success %")
    fig.tight_layout()
    save_figure(fig, path)
    plt.close(fig)


def write_matrix(cells: Sequence[Cell], out: Path) -> dict[str, str]:
    """``matrix.md``, ``.csv``, ``.json`` and ``.png`` in ``out``."""
    out.mkdir(parents=True, exist_ok=True)
    written = {kind: str(out / f"matrix.{kind}") for kind in ("md", "csv", "json", "png")}
    write_text_atomic(written["md"], matrix_markdown(cells))
    write_text_atomic(written["json"], json.dumps([asdict(c) for c in cells], indent=1))
    keys = ("episodes", "success_rate", "success_ci", "reached_rate", "reached_ci", "spl",
            "final_distance_mean")
    with open(written["csv"], "w", newline="") as f:
        writer = csv.writer(f)
        writer.writerow(["protocol", "version", "method", "success_on", *keys, "command"])
        for c in cells:
            writer.writerow([c.protocol, c.version, c.method, c.success_on,
                             *(json.dumps(c.summary[k]) if isinstance(c.summary[k], list)
                               else c.summary[k] for k in keys), c.command])
    if cells:
        plot_matrix(cells, written["png"])
    return written


def main(argv: list[str] | None = None) -> int:
    parser = command_parser("python -m homing_train.harness.matrix", __doc__)
    parser.add_argument("matrix_json", help="path of the matrix.json, relative to the README")
    parser.add_argument("--readme", default="README.md")
    parser.add_argument("--merge", action="append", default=[], metavar="NEW_JSON",
                        help="a newer run's matrix.json whose cells replace the same "
                             "protocol and method's cells first (repeatable)")
    args = parser.parse_args(argv)
    try:
        if args.merge:
            target = Path(args.readme).parent / args.matrix_json
            cells = load_cells(target)
            for path in args.merge:
                newer = load_cells(path)
                before = {(c.protocol, c.method): c.summary["episodes"] for c in cells}
                for cell in newer:
                    old = before.get((cell.protocol, cell.method), 0)
                    if cell.summary["episodes"] < old:
                        print(f"note: {cell.protocol} x {cell.method}: {old} episodes "
                              f"replaced by the {cell.summary['episodes']} of {path}")
                cells = merged_cells(cells, newer)
            write_matrix(cells, target.parent)
            print(f"merged {len(args.merge)} run(s) into {target}")
        else:
            markdown = Path(args.readme).parent / Path(args.matrix_json).with_suffix(".md")
            markdown.write_text(matrix_markdown(load_cells(markdown.with_suffix(".json"))))
            print(f"wrote {markdown}")
        update_readme(args.readme, args.matrix_json)
    except ValueError as err:
        parser.exit(2, f"error: {err}\n")
    print(f"wrote the matrix of {args.matrix_json} into {args.readme}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
