"""Which simulated task implements which library skill, and which robot kinds can run it."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

from . import science_tasks, tasks
from .scenario import ROBOT_KINDS
from .tasks import TaskFailed, TaskFunction

_DRONE = frozenset({"drone"})
_ROVERS = frozenset({"science_rover", "manipulator_rover"})
_ARM = frozenset({"manipulator_rover"})


@dataclass(frozen=True)
class TaskKind:
    """A simulated skill: its task, whether it needs battery, and the kinds that have it."""

    function: TaskFunction
    needs_power: bool = True
    kinds: frozenset[str] = frozenset(ROBOT_KINDS)


TASKS: Mapping[str, TaskKind] = {
    "navigate_to": TaskKind(tasks.navigate_to),
    "take_off": TaskKind(tasks.take_off, kinds=_DRONE),
    "land": TaskKind(tasks.land, kinds=_DRONE),
    "fly_over": TaskKind(tasks.fly_over, kinds=_DRONE),
    "explore": TaskKind(tasks.explore, kinds=frozenset({"science_rover"})),
    "return_to_lander": TaskKind(tasks.return_to_lander),
    "recharge": TaskKind(tasks.recharge, needs_power=False),
    "identify_stones": TaskKind(science_tasks.identify_stones, kinds=_ROVERS),
    "pick_stone": TaskKind(science_tasks.pick_stone, kinds=_ARM),
    "deposit_at_lander": TaskKind(science_tasks.deposit_at_lander, kinds=_ARM),
    "pick_box": TaskKind(science_tasks.pick_box, kinds=_ARM),
    "place_box": TaskKind(science_tasks.place_box, kinds=_ARM),
}


def task_for(skill: str, robot_kind: str) -> TaskKind:
    """The task of ``skill`` for a robot of ``robot_kind``; TaskFailed saying why if none."""
    kind = TASKS.get(skill)
    if kind is None:
        raise TaskFailed(f"unknown skill {skill!r} (known: {', '.join(sorted(TASKS))})")
    if robot_kind not in kind.kinds:
        raise TaskFailed(f"a {robot_kind.replace('_', ' ')} cannot {skill}")
    return kind
