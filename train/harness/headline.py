"""The headline comparison: what ``homing-suite`` runs with no arguments.

The held-out worlds (``unseen``, ``local-common``) and the papers' protocols, every
classical method where it applies and the default learned policy
(:data:`~homing_train.harness.policies.DEFAULT_POLICY`, ``--policy ppo``), at a
small episode count per protocol (:data:`HEADLINE_EPISODES`, chosen to take about 4
minutes on 2 cores with 2 workers). :func:`headline_table` is the compact methods x
protocols table it prints, :func:`reading` the plain-language reading of the numbers
that ends it.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Mapping, Sequence

import homing_baselines
from homing_train.harness.matrix import Cell, cell_methods
from homing_train.harness.policies import DEFAULT_POLICY, resolved_name, shipped_policies
from homing_train.harness.protocols import PROTOCOLS, Protocol

#: Episodes per setting of each headline protocol, in the order of the table: the
#: held-out worlds first, then the papers' protocols. ``yukim`` draws at least one
#: episode per start-distance bin (4), ``bekris-lab`` one per goal (6). Chosen by the
#: cost of a cell (CPU seconds per episode, summed over its methods, with ``random``
#: running to the step cap: about 29 per setting in ``unseen``, 27 in ``local-common``,
#: 6 in ``hong1991``, 10 in ``yukim``, 14 in ``bekris-lab``, 31 in ``briggs-corridors``
#: (3,000 steps), 64 in ``shiraishi-house`` (1,500 steps in the house)), before
#: min-warping, alv and did joined ``unseen`` and ``local-common``: now about 450 CPU
#: seconds in all, 4 minutes with 2 processes.
HEADLINE_EPISODES: dict[str, int] = {
    "unseen": 2, "local-common": 1, "hong1991": 6, "yukim": 4, "bekris-lab": 6,
    "briggs-corridors": 2, "shiraishi-house": 1}
#: The reference rows, not ranked by :func:`reading`: the privileged upper bound and the
#: lower bound.
BOUNDS = ("oracle", "random")


@dataclass(frozen=True)
class HeadlinePlan:
    """What the headline runs: ``protocols``, ``episodes`` per setting of each (by
    protocol name), ``methods`` (the rows, where they apply) and ``cell_episodes``: the
    episodes each cell of a protocol runs (every setting, every drawn task)."""

    protocols: tuple[Protocol, ...]
    episodes: Mapping[str, int]
    methods: tuple[str, ...]
    cell_episodes: Mapping[str, int]

    def describe(self) -> str:
        """One line per protocol: its episodes per cell and the methods that run it."""
        lines = []
        for p in self.protocols:
            rows = [m for m in cell_methods(p) if m in self.methods]
            n = self.cell_episodes[p.name]
            lines.append(f"{p.name}: {n} episode{'s' * (n != 1)} per cell "
                         f"({self.episodes[p.name]} per setting x {len(p.settings)} "
                         f"setting(s)), {', '.join(rows)}")
        return "\n".join(lines)


def default_methods(protocols: Sequence[Protocol]) -> list[str]:
    """Every classical method of ``protocols`` (in their order) and the default learned
    policy (``DEFAULT_POLICY``) where a protocol runs it; no other learned policy."""
    names: list[str] = []
    for p in protocols:
        names += [m for m in cell_methods(p) if m in homing_baselines.available()]
    if any(DEFAULT_POLICY in cell_methods(p) for p in protocols):
        names.append(DEFAULT_POLICY)
    return list(dict.fromkeys(names))


def headline_plan(episodes: int | None = None, methods: Sequence[str] | None = None,
                  seed: int | None = None) -> HeadlinePlan:
    """The headline's protocols (:data:`HEADLINE_EPISODES`; ``seed``: another draw of
    their episodes), ``episodes`` per setting for all of them instead of the headline's
    counts, and ``methods`` instead of :func:`default_methods` (``ppo``: the default
    learned policy)."""
    if episodes is not None and episodes < 1:
        raise ValueError(f"episodes must be >= 1, got {episodes}")
    protocols = tuple(PROTOCOLS[name] if seed is None else PROTOCOLS[name].reseeded(seed)
                      for name in HEADLINE_EPISODES)
    counts = {p.name: HEADLINE_EPISODES[p.name] if episodes is None else episodes
              for p in protocols}
    cell_episodes = {p.name: sum(len(s.episode_tasks(counts[p.name], p.seed))
                                 for s in p.settings) for p in protocols}
    chosen = [resolved_name(m) for m in methods or []]
    return HeadlinePlan(protocols, counts, tuple(chosen or default_methods(protocols)),
                        cell_episodes)


def check_methods(plan: HeadlinePlan) -> None:
    """``ValueError`` naming the plan's methods that are neither a registered controller
    nor a shipped policy, and those that are."""
    known = homing_baselines.available() + sorted(shipped_policies())
    unknown = [m for m in plan.methods if m not in known]
    if unknown:
        raise ValueError(f"unknown methods {unknown}; available: {known}")


def _pct(cell: Cell, unit: str = "") -> str:
    lo, hi = cell.summary["success_ci"]
    return f"{100 * cell.summary['success_rate']:.0f}{unit} [{100 * lo:.0f}, {100 * hi:.0f}]"


def headline_table(cells: Sequence[Cell]) -> str:
    """Success % [95% Wilson interval] by method (rows) and protocol (columns), the
    episodes per cell in the column head (in the cell where a protocol's cells differ);
    methods with privileged data marked ``*`` and named below."""
    protocols = list(dict.fromkeys(c.protocol for c in cells))
    methods = list(dict.fromkeys(c.method for c in cells))
    by = {(c.protocol, c.method): c for c in cells}
    counts = {p: {c.summary["episodes"] for c in cells if c.protocol == p} for p in protocols}
    head = [f"{p} (n={next(iter(counts[p]))})" if len(counts[p]) == 1 else p
            for p in protocols]
    privileged = {m: _privileged(m, cells) for m in methods}
    lines = ["| method | " + " | ".join(head) + " |", "|---|" + "---:|" * len(protocols)]
    for m in methods:
        row = []
        for p in protocols:
            cell = by.get((p, m))
            n = "" if cell is None or len(counts[p]) == 1 else f" n={cell.summary['episodes']}"
            row.append("" if cell is None else _pct(cell) + n)
        lines.append(f"| {m}{'*' if privileged[m] else ''} | " + " | ".join(row) + " |")
    notes = [f"*{m}: {why}" for m, why in privileged.items() if why]
    return ("Success % [95% Wilson interval]: stopped at the goal (within 0.15 m; 0.10 m in "
            "shiraishi-house; in front of the landmark in briggs-corridors); n = episodes per "
            "cell; blank: the method does not apply.\n\n" + "\n".join(lines) + "\n\n"
            + "".join(f"{n}\n" for n in notes))


def _privileged(method: str, cells: Sequence[Cell]) -> str:
    """What beyond pixels ``method`` uses (its controller's, its cells')."""
    own = ([homing_baselines.controller_class(method).privileged]
           if method in homing_baselines.available() else [])
    found = own + [c.privileged for c in cells if c.method == method]
    return "; ".join(dict.fromkeys(p for p in found if p))


def overlap(a: Cell, b: Cell) -> bool:
    """Whether the 95% success intervals of two cells overlap."""
    (a_lo, a_hi), (b_lo, b_hi) = a.summary["success_ci"], b.summary["success_ci"]
    return a_lo <= b_hi and b_lo <= a_hi


def _named(cell: Cell) -> str:
    return f"{cell.method} {_pct(cell, '%')}"


def _listed(cells: Sequence[Cell]) -> str:
    """The cells named (:func:`_named`) as a list in words: "a, b and c"."""
    names = [_named(c) for c in cells]
    return " and ".join(filter(None, [", ".join(names[:-1]), names[-1]]))


def protocol_reading(cells: Sequence[Cell]) -> str:
    """One sentence on one protocol's cells: which method (not a bound, :data:`BOUNDS`)
    leads, and whether its interval clears the others' or overlaps them."""
    ranked = sorted((c for c in cells if c.method not in BOUNDS),
                    key=lambda c: -c.summary["success_rate"])
    name = cells[0].protocol
    if not ranked:
        return f"{name}: only the bounds ran."
    leader, rest = ranked[0], ranked[1:]
    if leader.summary["success_rate"] == 0:
        return f"{name}: no method (the bounds aside) stopped at the goal."
    if not rest:
        return f"{name}: {_named(leader)} (the only method here besides the bounds)."
    tied = [c for c in rest if overlap(leader, c)]
    if not tied:
        return (f"{name}: {_named(leader)} leads; its interval clears every other "
                f"method's (next: {_named(rest[0])}).")
    apart = [c for c in rest if c not in tied]
    ahead = f"; it is ahead of {_listed(apart)} (intervals apart)" if apart else ""
    return (f"{name}: {_named(leader)} is first, but its interval overlaps "
            f"{_listed(tied)}: no ranking can be claimed between them"
            f"{ahead}.")


def learned_reading(cells: Sequence[Cell], held_out: str = "unseen") -> str:
    """How each learned policy (a method that is not a controller) compares with the best
    classical method (not a bound) in the ``held_out`` protocol; "" without both."""
    here = [c for c in cells if c.protocol == held_out and c.method not in BOUNDS]
    classical = sorted((c for c in here if c.method in homing_baselines.available()),
                       key=lambda c: -c.summary["success_rate"])
    sentences = []
    for learned in (c for c in here if c.method not in homing_baselines.available()):
        if not classical:
            continue
        best = classical[0]
        if overlap(learned, best):
            verdict = "the intervals overlap, so no difference can be claimed"
        elif learned.summary["success_rate"] > best.summary["success_rate"]:
            verdict = "ahead, the intervals apart"
        else:
            verdict = "behind, the intervals apart"
        sentences.append(f"On held-out worlds ({held_out}) the learned policy {_named(learned)} "
                         f"against the best classical method, {_named(best)}: {verdict}.")
    return " ".join(sentences)


def reading(cells: Sequence[Cell]) -> str:
    """The plain-language reading of the headline's numbers: each protocol's leader and
    whether the intervals allow a ranking, the learned policy on held-out worlds, and
    the episode counts the intervals come from."""
    protocols = list(dict.fromkeys(c.protocol for c in cells))
    lines = [protocol_reading([c for c in cells if c.protocol == p]) for p in protocols]
    learned = learned_reading(cells)
    counts = sorted({c.summary["episodes"] for c in cells})
    span = f"{counts[0]}" if len(counts) == 1 else f"{counts[0]}-{counts[-1]}"
    return ("Reading (oracle and random are the upper and lower bounds, not ranked):\n"
            + "".join(f"- {line}\n" for line in lines)
            + (f"- {learned}\n" if learned else "")
            + f"- Each cell has {span} episodes, so the intervals are wide; more: "
              f"homing-suite --episodes N (per setting), or --protocols all for each "
              f"protocol's own count.\n")
