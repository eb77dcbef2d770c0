"""The mission's guard of skill targets against the newest known site (see :mod:`..world.site`)."""

from __future__ import annotations

import logging
from collections.abc import Iterator, Sequence

from ..errors import RuleViolation
from ..model.changes import Change
from ..model.model import SkillInstance, SkillStatus
from ..model.state import MissionState
from ..skills.library import Library, ParameterSpec
from ..skills.params import Pose, Value
from ..world.site import SiteModel, check_site

_log = logging.getLogger(__name__)


class SiteGuard:
    """The newest site the mission knows, and the target checks it runs against it.

    The mission owns one; the server hands it each site its map provider publishes.
    """

    def __init__(self) -> None:
        self.site: SiteModel | None = None
        self._said_unchecked = False
        self._library_checks: tuple[Library, bool] | None = None  # the answer for a library

    def _checks_targets(self, library: Library) -> bool:
        """Whether any skill of ``library`` has a parameter checked against the site."""
        if self._library_checks is None or self._library_checks[0] is not library:
            checks = any(
                param.check_target is not None
                for skills in library.models.values()
                for spec in skills.values()
                for param in spec.parameters
            )
            self._library_checks = (library, checks)
        return self._library_checks[1]

    def update(self, site: SiteModel) -> None:
        """Check targets against ``site`` from now on (skills already added stay as they are)."""
        self.site = check_site(site)

    def check(self, library: Library, state: MissionState, change: Change) -> None:
        """Refuse ``change`` if a blueprint skill it puts has a target the site rules out.

        Only checked parameters whose value the change sets anew count: editing a label
        never fails for a target that was fine when the site was unknown.
        """
        if not self._checks_targets(library):  # most libraries check no target
            return
        checked: dict[tuple[str, str], tuple[ParameterSpec, ...]] = {}  # per agent and skill
        for skill, is_new in _blueprint_skills(state, change):
            kind = (skill.agent, skill.skill)
            params = checked.get(kind)
            if params is None:
                spec = library.skill(skill.agent, skill.skill)
                params = checked[kind] = tuple(
                    p for p in spec.parameters if p.check_target is not None
                )
            if not params:  # most skills: nothing of theirs is checked against the site
                continue
            old = None if is_new or change.replacement else state.skill(skill.id)
            for param in params:
                value = skill.params.get(param.name)
                if value is None:
                    continue
                if old is not None and old.params.get(param.name) == value:
                    continue
                if self.site is None:
                    self._say_unchecked()
                    return
                self._check_value(self.site, skill, is_new, param, value)

    def _check_value(
        self,
        site: SiteModel,
        skill: SkillInstance,
        is_new: bool,
        param: ParameterSpec,
        value: Value,
    ) -> None:
        assert param.check_target is not None
        for what, x, y in _points(param.name, value):
            problem = site.problem(param.check_target, skill.agent, x, y)
            if problem:
                owner = f"{skill.agent}'s '{skill.skill}'" + ("" if is_new else f" ({skill.id})")
                marker = skill.bindings.get(param.name)
                bound = f", bound to marker '{marker}'," if marker else ""
                raise RuleViolation(f"{what} of {owner}{bound} {problem}")

    def _say_unchecked(self) -> None:
        if not self._said_unchecked:
            self._said_unchecked = True
            _log.info(
                "skill targets are not checked against the site: no site map is known yet "
                "(the simulator or a map provider publishes one)"
            )


def _blueprint_skills(state: MissionState, change: Change) -> Iterator[tuple[SkillInstance, bool]]:
    """The blueprint skills a change puts, each with whether it is new to the operator."""
    if change.replacement is not None:
        for task in change.replacement.tasks.values():
            yield from ((s, False) for s in task if s.status is SkillStatus.IDLE)
        return
    for placed in change.put_skills:
        if placed.skill.status is SkillStatus.IDLE:
            yield placed.skill, not state.has_skill(placed.skill.id)


def _points(name: str, value: Value) -> Sequence[tuple[str, float, float]]:
    """The points of a pose or an area value, each with how a sentence names it."""
    if isinstance(value, Pose):
        return [(f"{name} ({value.x:.1f}, {value.y:.1f})", value.x, value.y)]
    if isinstance(value, list):
        corners = [(float(p["x"]), float(p["y"])) for p in value if isinstance(p, dict)]
        return [
            (f"corner {i} ({x:.1f}, {y:.1f}) of {name}", x, y)
            for i, (x, y) in enumerate(corners, 1)
        ]
    return []
