"""The directed landmark visibility graph of Briggs, Scharstein et al. 2000 (§4), with
deterministic shortest paths (§4.1-4.2) and expected shortest paths (§4.3).

An edge ``a -> b`` says landmark ``b`` was seen from the place in front of landmark
``a``. It carries the estimated distance (m, from ``b``'s apparent size) and the angle
(radians, in the robot's global frame, from ``b``'s horizontal image position) of the
last sighting, the travelled distance once the edge has been driven (§4.1: "further
annotated with the measured distance"), and the visibility history: how often ``b`` was
looked for from ``a`` and how often it was seen. Edge length: the travelled distance if
known, else the estimate.

Deterministic planning (§4.2) uses the edges whose last observation saw the target
(:meth:`VisibilityGraph.shortest_path`, networkx Dijkstra); an edge whose target was
not visible when expected is marked so and the path replanned.

Probabilistic planning (§4.3): ``p_ab`` = seen / looked (the paper's simplest estimate,
independent observations). Every node has a self-edge (stay and take another picture)
of cost ``stay_cost`` > 0 and probability 1. The expected length ``E_x`` of the best
policy to the goal satisfies, with the out-edges of ``x`` sorted by
``c_y = l_xy + E_y`` ascending and each visible independently with ``p_xy``,

    E_x = sum_i c_(i) p_(i) prod_{j<i} (1 - p_(j)) + prod_j (1 - p_(j)) (stay_cost + E_x),

(the robot takes the best visible edge, or stays). :meth:`expected_lengths` solves it by
value iteration (the paper's non-discounted MDP, [9]); :meth:`best_next` then picks,
among the landmarks visible now, the one minimising ``l_xy + E_y``, or stays.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import networkx as nx


@dataclass
class EdgeInfo:
    """What is known about edge ``a -> b`` (metres, radians)."""

    distance: float
    angle: float
    travelled: float | None = None
    looked: int = 0
    seen: int = 0
    visible: bool = True

    @property
    def length(self) -> float:
        return self.travelled if self.travelled is not None else self.distance

    @property
    def probability(self) -> float:
        return self.seen / self.looked if self.looked else 1.0


class VisibilityGraph:
    """The landmark visibility graph; nodes are landmark ids."""

    def __init__(self) -> None:
        self.graph = nx.DiGraph()

    def edge(self, a: int, b: int) -> EdgeInfo | None:
        data = self.graph.get_edge_data(a, b)
        return None if data is None else data["info"]

    def observe(self, at: int, seen: dict[int, tuple[float, float]]) -> None:
        """One look around from in front of landmark ``at``: ``seen`` maps each landmark
        detected to its (estimated distance, global angle). Known edges from ``at`` count
        a look; seen ones a sighting; new ones are added."""
        self.graph.add_node(at)
        for b in list(self.graph.successors(at)):
            info = self.edge(at, b)
            info.looked += 1
            info.visible = b in seen
        for b, (distance, angle) in seen.items():
            if b == at:
                continue
            info = self.edge(at, b)
            if info is None:
                self.graph.add_edge(at, b, info=EdgeInfo(distance, angle, looked=1, seen=1))
            else:
                info.seen += 1
                info.distance, info.angle = distance, angle

    def traversed(self, a: int, b: int, distance: float) -> None:
        """Record the distance (m) actually travelled along ``a -> b``."""
        info = self.edge(a, b)
        if info is not None:
            info.travelled = float(distance)

    def mark_invisible(self, a: int, b: int) -> None:
        """``b`` was not seen from ``a`` when the plan expected it (§4.2)."""
        info = self.edge(a, b)
        if info is not None:
            info.looked += 1
            info.visible = False

    def shortest_path(self, start: int, goal: int) -> list[int] | None:
        """Shortest path over the edges believed visible (§4.2), or ``None``."""
        if start not in self.graph or goal not in self.graph:
            return None
        usable = nx.subgraph_view(
            self.graph, filter_edge=lambda a, b: self.graph[a][b]["info"].visible)
        try:
            return nx.shortest_path(usable, start, goal,
                                    weight=lambda a, b, d: d["info"].length)
        except nx.NetworkXNoPath:
            return None

    def reaching(self, goal: int) -> set[int]:
        """The landmarks from which a path over edges believed visible leads to
        ``goal`` (``goal`` itself included, if known)."""
        if goal not in self.graph:
            return set()
        usable = nx.subgraph_view(
            self.graph, filter_edge=lambda a, b: self.graph[a][b]["info"].visible)
        return nx.ancestors(usable, goal) | {goal}

    def expected_lengths(self, goal: int, stay_cost: float, tolerance: float = 1e-6,
                         max_iterations: int = 10_000) -> dict[int, float]:
        """``E_x`` (m) for every node (§4.3), by value iteration; ``inf`` where the goal
        cannot be reached over edges of non-zero probability."""
        if not stay_cost > 0:
            raise ValueError(f"stay_cost must be > 0 metres, got {stay_cost!r}")
        reach = nx.ancestors(nx.subgraph_view(
            self.graph, filter_edge=lambda a, b: self.graph[a][b]["info"].probability > 0),
            goal) if goal in self.graph else set()
        values = {x: (0.0 if x == goal else (0.0 if x in reach else math.inf))
                  for x in self.graph}
        for _ in range(max_iterations):
            change = 0.0
            for x in reach:
                new = self._expected_step(x, values, stay_cost)
                change = max(change, abs(new - values[x]))
                values[x] = new
            if change < tolerance:
                break
        return values

    def _expected_step(self, x: int, values: dict[int, float], stay_cost: float) -> float:
        options = sorted((info.length + values[y], info.probability)
                         for y, d in self.graph[x].items()
                         for info in (d["info"],) if math.isfinite(values[y]))
        expected, none_yet = 0.0, 1.0
        for cost, prob in options:
            expected += none_yet * prob * cost
            none_yet *= 1 - prob
        return expected + none_yet * (stay_cost + values[x])

    def best_next(self, at: int, visible: set[int], values: dict[int, float],
                  stay_cost: float) -> int:
        """The landmark to head for from ``at`` given the ones ``visible`` now and the
        expected lengths ``values``; ``at`` itself means stay and look again (§4.3)."""
        best, best_cost = at, stay_cost + values.get(at, math.inf)
        for y in visible:
            info = self.edge(at, y)
            if info is None or y not in values:
                continue
            cost = info.length + values[y]
            if cost < best_cost:
                best, best_cost = y, cost
        return best
