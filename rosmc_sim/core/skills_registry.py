"""Which simulated skill function implements which library skill, and which robot kinds have it."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

from . import science_runs, skill_runs
from .scenario import ROBOT_KINDS
from .skill_runs import SkillFailed, SkillFunction

_DRONE = frozenset({"drone"})
_ROVERS = frozenset({"science_rover", "manipulator_rover"})
_ARM = frozenset({"manipulator_rover"})


@dataclass(frozen=True)
class SimSkill:
    """A simulated skill: its function, whether it needs battery, and the kinds that have it."""

    function: SkillFunction
    needs_power: bool = True
    kinds: frozenset[str] = frozenset(ROBOT_KINDS)


SIM_SKILLS: Mapping[str, SimSkill] = {
    "navigate_to": SimSkill(skill_runs.navigate_to),
    "take_off": SimSkill(skill_runs.take_off, kinds=_DRONE),
    "land": SimSkill(skill_runs.land, kinds=_DRONE),
    "fly_over": SimSkill(skill_runs.fly_over, kinds=_DRONE),
    "explore": SimSkill(skill_runs.explore, kinds=frozenset({"science_rover"})),
    "return_to_lander": SimSkill(skill_runs.return_to_lander),
    "recharge": SimSkill(skill_runs.recharge, needs_power=False),
    "identify_stones": SimSkill(science_runs.identify_stones, kinds=_ROVERS),
    "pick_stone": SimSkill(science_runs.pick_stone, kinds=_ARM),
    "deposit_at_lander": SimSkill(science_runs.deposit_at_lander, kinds=_ARM),
    "pick_box": SimSkill(science_runs.pick_box, kinds=_ARM),
    "place_box": SimSkill(science_runs.place_box, kinds=_ARM),
}


def sim_skill_for(skill: str, robot_kind: str) -> SimSkill:
    """The simulated ``skill`` for a robot of ``robot_kind``; SkillFailed saying why if none."""
    kind = SIM_SKILLS.get(skill)
    if kind is None:
        raise SkillFailed(f"unknown skill {skill!r} (known: {', '.join(sorted(SIM_SKILLS))})")
    if robot_kind not in kind.kinds:
        raise SkillFailed(f"a {robot_kind.replace('_', ' ')} cannot {skill}")
    return kind
