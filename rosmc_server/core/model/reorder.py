"""Reorders as moves: from a whole new order to moves, and from moves back to an order.

A reorder travels as a list of moves (a skill and its index once moved, applied one
after the other; see ``rosmc/SkillMove``). Played one by one, each move shifts the
skills between its two places, so ``m`` moves over a task of ``n`` skills cost
``m * n``: a random new order of 25,000 skills took seconds. Both directions here cost
``n`` plus the moves instead:

* :func:`moves_between` keeps a longest run of skills already in their new relative order
  (the fewest moves) and moves each other skill, in the new order, to just after its
  new predecessor. Such *canonical* moves have a closed form: the index of the ``k``-th
  move is ``k`` (the skills moved so far, all before it) plus the staying skills before
  it in the new order plus the skills not yet moved that still sit before that place.
* :func:`play_moves` inverts that form: for canonical moves (from any planner that
  places each skill after its new predecessor) it gives the resulting order in one
  pass; for any other list of moves it answers None and the caller plays them one by one.
"""

from __future__ import annotations

import bisect
from collections.abc import Sequence
from itertools import compress

from .moves import SkillMove, move_columns

NOT_A_PERMUTATION = "the new order is not a permutation of the current one"
_IS_REGION = (-1).__lt__  # a region number, not the -1 of a staying skill


def canonical_moves(
    current: Sequence[str], order: Sequence[str], offset: int = 0
) -> tuple[list[str], list[int]]:
    """The fewest moves, as their ids and indexes, that turn ``current`` into ``order``.

    ``current`` holds distinct ids; ``order`` must be a permutation of it, else
    ValueError (checked on the way, without sets of both). Indexes are ``offset`` plus
    the index in the sequence (``current`` is a task's stretch starting at ``offset``).
    Skills that keep their place at either end take no part. Cost: ``n log n`` for the
    longest run (in C, through :mod:`bisect`), ``n`` for the rest.
    """
    if len(current) != len(order):
        raise ValueError(NOT_A_PERMUTATION)
    pairs = zip(current, order, strict=True)
    head = next((i for i, (was, now) in enumerate(pairs) if was != now), len(order))
    tail = len(order)
    while tail > head and current[tail - 1] == order[tail - 1]:
        tail -= 1
    current, order, offset = current[head:tail], order[head:tail], offset + head
    position = dict(zip(order, range(len(order)), strict=True))
    try:
        targets = list(map(position.__getitem__, current))
    except KeyError:  # an id of ``current`` is missing from ``order``
        raise ValueError(NOT_A_PERMUTATION) from None
    if len(position) != len(order):  # ``order`` names an id twice
        raise ValueError(NOT_A_PERMUTATION)
    staying = _longest_increasing(targets)
    # Per place in the new order: the region of the skill moved there (how many staying
    # skills are before it now), or -1 where a staying skill is; per region, how many
    # moved skills wait there. Lists, not dicts: the loops index them by place.
    region = [-1] * len(order)
    waiting = [0] * (staying.count(1) + 1)
    passed = 0
    for target in targets:
        if staying[target]:
            passed += 1
        else:
            region[target] = passed
            waiting[passed] += 1
    ids = list(compress(order, map(_IS_REGION, region)))
    indexes: list[int] = []
    add = indexes.append
    moved = offset  # ``offset`` + the skills moved so far (all before the next one)
    before = 0  # staying skills before the next moved one, in the new order
    unmoved_before = 0  # moved skills not moved yet in the regions below ``before``
    for number in region:
        if number < 0:
            unmoved_before += waiting[before]
            before += 1
        else:
            waiting[number] -= 1
            if number < before:
                unmoved_before -= 1
            add(moved + before + unmoved_before)
            moved += 1
    return ids, indexes


def play_moves(
    current: Sequence[str], moves: Sequence[SkillMove], offset: int = 0
) -> list[str] | None:
    """``current`` after ``moves`` (played one after the other), or None if not canonical.

    ``current`` is a task's stretch starting at index ``offset`` that holds every moved
    skill and every index moved to. Canonical moves (see the module's docstring) are
    decoded in one pass; for others the answer is None, never a wrong order.
    """
    moved, indexes = move_columns(moves)
    moved_set = set(moved)
    if len(moved_set) != len(moved):
        return None
    region: dict[str, int] = {}
    staying: list[str] = []
    for skill_id in current:
        if skill_id in moved_set:
            region[skill_id] = len(staying)
        else:
            staying.append(skill_id)
    if len(region) != len(moved):
        return None  # a move names a skill outside the stretch
    waiting = [0] * (len(staying) + 1)
    for number in region.values():
        waiting[number] += 1
    chains: dict[int, list[str]] = {}  # staying skills before a run of moved ones -> the run
    before = unmoved_before = 0
    for done, (skill_id, index) in enumerate(zip(moved, indexes, strict=True)):
        number = region[skill_id]
        waiting[number] -= 1
        if number < before:
            unmoved_before -= 1
        wanted = index - offset - done
        while before + unmoved_before < wanted and before < len(staying):
            unmoved_before += waiting[before]
            before += 1
        if before + unmoved_before != wanted:
            return None
        chains.setdefault(before, []).append(skill_id)
    result: list[str] = []
    start = 0
    for at, run in chains.items():  # in increasing ``at``: ``before`` never decreases
        result += staying[start:at]
        result += run
        start = at
    result += staying[start:]
    return result


def play_one_by_one(
    current: Sequence[str], moves: Sequence[SkillMove], offset: int = 0
) -> list[str]:
    """``current`` after ``moves``, each played as the definition says (the simple way)."""
    result = list(current)
    for move in moves:
        result.remove(move.skill_id)
        result.insert(move.index - offset, move.skill_id)
    return result


def _longest_increasing(values: Sequence[int]) -> bytearray:
    """Flags, by value, of the values of a longest increasing run (subsequence) of
    ``values``, a permutation of ``range(len(values))``."""
    tails: list[int] = []  # the smallest last value of an increasing run of each length
    ends: list[int] = []  # where in ``values`` that run ends
    previous: list[int] = []
    for index, value in enumerate(values):
        length = bisect.bisect_left(tails, value)
        if length == len(tails):
            tails.append(value)
            ends.append(index)
        else:
            tails[length] = value
            ends[length] = index
        previous.append(ends[length - 1] if length else -1)
    run = bytearray(len(values))
    index = ends[-1] if ends else -1
    while index >= 0:
        run[values[index]] = 1
        index = previous[index]
    return run
