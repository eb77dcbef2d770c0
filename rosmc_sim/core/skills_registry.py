"""Which simulated task implements which library skill."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

from . import science_tasks, tasks
from .tasks import TaskFunction


@dataclass(frozen=True)
class TaskKind:
    """A simulated skill: its task, and whether it needs battery to run."""

    function: TaskFunction
    needs_power: bool = True


TASKS: Mapping[str, TaskKind] = {
    "navigate_to": TaskKind(tasks.navigate_to),
    "take_off": TaskKind(tasks.take_off),
    "land": TaskKind(tasks.land),
    "fly_over": TaskKind(tasks.fly_over),
    "explore": TaskKind(tasks.explore),
    "return_to_lander": TaskKind(tasks.return_to_lander),
    "recharge": TaskKind(tasks.recharge, needs_power=False),
    "identify_stones": TaskKind(science_tasks.identify_stones),
    "pick_stone": TaskKind(science_tasks.pick_stone),
    "deposit_at_lander": TaskKind(science_tasks.deposit_at_lander),
    "pick_box": TaskKind(science_tasks.pick_box),
    "place_box": TaskKind(science_tasks.place_box),
}
