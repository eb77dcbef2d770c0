"""Deadlocks between barriers: a cycle of "runs before" edges through barrier groups.

Pure graph code over skill ids, shared by the server's barrier checks
(:mod:`.barriers`) and what the GUIs enable (:mod:`.legality`).
"""

from __future__ import annotations

import itertools
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass


@dataclass(frozen=True)
class OrderEdge:
    """``before`` runs before ``after`` on ``agent``."""

    agent: str
    before: str
    after: str


def find_deadlock(
    tasks: Mapping[str, Sequence[str]], groups: Iterable[Sequence[str]]
) -> list[OrderEdge] | None:
    """Return the task-order edges of a cycle through the barrier groups, or None.

    ``tasks`` maps each agent to its skill ids in order; ``groups`` are the
    barriers' member ids. A skill in no barrier only passes "runs before" on
    along its task, so each task shrinks to its barrier members in order and
    the graph has one node per barrier: small, whatever the mission's size.
    """
    point: dict[str, str] = {}
    for number, members in enumerate(groups):
        for skill_id in members:
            point[skill_id] = f"barrier#{number}"
    graph: dict[str, list[tuple[str, OrderEdge]]] = {}
    for agent, ids in tasks.items():
        members = [skill_id for skill_id in ids if skill_id in point]
        for before, after in itertools.pairwise(members):
            edge = OrderEdge(agent, before, after)
            graph.setdefault(point[before], []).append((point[after], edge))
    return _find_cycle(graph)


def _find_cycle(
    graph: Mapping[str, list[tuple[str, OrderEdge]]],
) -> list[OrderEdge] | None:
    done: set[str] = set()
    for root in graph:
        if root in done:
            continue
        on_path: dict[str, int] = {root: 0}
        path_edges: list[OrderEdge] = []
        stack = [(root, iter(graph.get(root, ())))]
        while stack:
            node, edges = stack[-1]
            step = next(edges, None)
            if step is None:
                stack.pop()
                on_path.pop(node)
                done.add(node)
                if path_edges:
                    path_edges.pop()
                continue
            target, edge = step
            if target in on_path:
                return [*path_edges[on_path[target] :], edge]
            if target not in done:
                on_path[target] = len(path_edges) + 1
                path_edges.append(edge)
                stack.append((target, iter(graph.get(target, ()))))
    return None


def describe_cycle(cycle: Sequence[OrderEdge]) -> str:
    """Name a deadlock cycle in words, e.g. ``A runs x1 before y1, B runs y2 before x2``."""
    return ", ".join(f"{e.agent} runs '{e.before}' before '{e.after}'" for e in cycle)
