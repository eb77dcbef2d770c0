"""Barrier members by pair of agents: the next member of an agent's task shared with another.

Barriers that do not deadlock keep every pair of agents in step: along agent A's task,
the members that share a barrier with agent B have their partners on B in the same order
(two out of step would wait for each other). So the earliest place on B that A's task
leads to from any point, in one barrier, is the partner of the first member after that
point that shares a barrier with B: a binary search in this index. The deadlock check of
a new barrier (:func:`..rules.barriers.check_new_barrier`) asks only such questions.
"""

from __future__ import annotations

import bisect
from collections.abc import Callable, Iterable


class PairIndex:
    """Per ordered pair of agents (A, B): A's members that share a barrier with B, by key.

    Keys are the mission state's position keys of A's task; the state tells the index
    when a member comes or goes and when A's keys are given anew.
    """

    def __init__(self) -> None:
        self._keys: dict[tuple[str, str], list[int]] = {}
        self._ids: dict[tuple[str, str], list[str]] = {}
        self._partners: dict[str, dict[str, None]] = {}  # agent -> agents it shares with
        self._pairs_of: dict[str, tuple[tuple[str, str], ...]] = {}  # member -> its pairs

    def clear(self) -> None:
        """Forget every member."""
        self._keys.clear()
        self._ids.clear()
        self._partners.clear()
        self._pairs_of.clear()

    def add(self, skill_id: str, agent: str, key: int, partners: Iterable[str]) -> None:
        """``skill_id`` at ``key`` on ``agent`` shares a barrier with ``partners``' agents."""
        self.remove(skill_id, key)
        pairs = tuple((agent, other) for other in dict.fromkeys(partners) if other != agent)
        for pair in pairs:
            keys = self._keys.setdefault(pair, [])
            at = bisect.bisect_left(keys, key)
            keys.insert(at, key)
            self._ids.setdefault(pair, []).insert(at, skill_id)
            self._partners.setdefault(agent, {})[pair[1]] = None
        self._pairs_of[skill_id] = pairs

    def remove(self, skill_id: str, key: int) -> None:
        """``skill_id``, at ``key``, shares no barrier any more (nothing if it did not)."""
        for pair in self._pairs_of.pop(skill_id, ()):
            keys, ids = self._keys[pair], self._ids[pair]
            at = bisect.bisect_left(keys, key)
            if at >= len(ids) or ids[at] != skill_id:
                at = ids.index(skill_id)
            del ids[at]
            del keys[at]

    def rekey(self, agent: str, key_of: Callable[[str], int]) -> None:
        """``agent``'s keys were given anew: sort its members again by ``key_of``."""
        for other in self._partners.get(agent, {}):
            pair = (agent, other)
            ids = self._ids.get(pair)
            if ids:
                ids.sort(key=key_of)
                self._keys[pair] = [key_of(skill_id) for skill_id in ids]

    def partners(self, agent: str) -> Iterable[str]:
        """The agents ``agent`` shares (or shared) a barrier with."""
        return self._partners.get(agent, {})

    def first_after(self, agent: str, other: str, key: int) -> str | None:
        """The first member of ``agent``'s task after ``key`` that shares a barrier with
        ``other``, if any."""
        keys = self._keys.get((agent, other))
        if not keys:
            return None
        at = bisect.bisect_right(keys, key)
        return self._ids[(agent, other)][at] if at < len(keys) else None
