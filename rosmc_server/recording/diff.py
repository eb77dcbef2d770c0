"""What changed in a recording between two moments: ``rosmc diff FILE T1 T2``.

A moment is a revision (``r42``), seconds since the recording started (``90``, ``90s``,
``1:30``, ``1:02:03``) or a wall-clock ISO time (``2026-11-24T00:31:00+00:00``; without a
zone, UTC). The two missions are compared skill by skill (parameter by parameter),
barrier by barrier and marker by marker.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from datetime import UTC, datetime
from typing import TYPE_CHECKING, TypeVar

from ..core import InvalidRequest, MissionState, SkillInstance, TaskMarker
from ..core.validation import excerpt

if TYPE_CHECKING:  # only for annotations: --help imports this module and stays fast
    from .history import MissionHistory

_T = TypeVar("_T")
_SLACK = 1e-6  # seconds: a time printed to the nanosecond reads back a hair later
_CLOCK = re.compile(r"(?:(\d+):)?(\d+):(\d+(?:\.\d*)?)")
WHEN_HELP = (
    "rN (revision N), seconds since the start (90, 90s, 1:30, 1:02:03) "
    "or an ISO time (2026-11-24T00:31:00+00:00; no zone means UTC)"
)


@dataclass(frozen=True)
class Moment:
    """A resolved moment of a recording: the mission then and how to name it."""

    state: MissionState
    label: str  # as the user wrote it, normalized ("r42", "90 s", an ISO time)
    seconds: float  # when the revision shown was journaled, since the start


@dataclass(frozen=True)
class FieldChange:
    """One field of one skill, barrier or marker that differs."""

    subject: str  # skill id, barrier id or marker name
    field: str  # "label", "param altitude", "binding position", "status", ...
    before: str
    after: str


@dataclass(frozen=True)
class MissionDiff:
    """Everything that differs between two revisions of a mission."""

    before: Moment
    after: Moment
    skills_added: tuple[str, ...]  # described as "id (agent skill 'label')"
    skills_removed: tuple[str, ...]
    edits: tuple[FieldChange, ...]  # what the operator writes: label, params, bindings, limits
    statuses: tuple[FieldChange, ...]  # what execution changes: status, attempt, resolution
    barriers_added: tuple[str, ...]  # described as "id: a + b"
    barriers_removed: tuple[str, ...]
    markers_added: tuple[str, ...]
    markers_removed: tuple[str, ...]
    marker_changes: tuple[FieldChange, ...]

    @property
    def is_empty(self) -> bool:
        """Whether the two missions are the same."""
        return not any(
            getattr(self, name)
            for name in self.__dataclass_fields__
            if name not in ("before", "after")
        )


def resolve_when(history: MissionHistory, text: str) -> Moment:
    """The mission at ``text`` (see :data:`WHEN_HELP`).

    Raises:
        InvalidRequest: ``text`` is none of the accepted forms, or a time outside the
            recording (before its start or after its end).
        NotFound: A revision the recording does not hold.
    """
    when = text.strip()
    target = parse_when(when, history.start)
    if target.revision is not None:
        state = history.at_revision(target.revision)
        label = f"r{state.revision}"
    else:
        seconds = target.seconds
        if not 0.0 <= seconds <= history.duration + _SLACK:
            raise InvalidRequest(
                f"{excerpt(when)} is outside the recording ({seconds:+.1f} s from its start; "
                f"it lasts {history.duration:.1f} s)"
            )
        state = history.at_time(seconds)
        label = when if "T" in when else f"{seconds:g} s"
    info = next(r for r in history.revisions if r.revision == state.revision)
    return Moment(state, label, history.seconds(info.log_time))


@dataclass(frozen=True)
class When:
    """A moment as written: a revision, or else seconds since the recording started."""

    revision: int | None
    seconds: float = 0.0


def parse_when(text: str, start: int) -> When:
    """What ``text`` (see :data:`WHEN_HELP`) names in a recording that started at log time
    ``start`` (ns).

    Raises:
        InvalidRequest: ``text`` is none of the accepted forms.
    """
    when = text.strip()
    revision = re.fullmatch(r"[rR](\d+)", when)
    if revision:
        return When(int(revision.group(1)))
    return When(None, _seconds(start, when))


def _seconds(start: int, when: str) -> float:
    clock = _CLOCK.fullmatch(when)
    if clock:
        hours, minutes, seconds = clock.groups()
        return int(hours or 0) * 3600 + int(minutes) * 60 + float(seconds)
    try:
        return float(when[:-1] if when.endswith("s") else when)
    except ValueError:
        pass
    try:
        moment = datetime.fromisoformat(when)
    except ValueError:
        raise InvalidRequest(f"cannot read {excerpt(when)} as a time: give {WHEN_HELP}") from None
    if moment.tzinfo is None:
        moment = moment.replace(tzinfo=UTC)
    return (round(moment.timestamp() * 1e9) - start) / 1e9


def diff_missions(before: Moment, after: Moment) -> MissionDiff:
    """Compare the missions of two moments."""
    old = {skill.id: skill for skill in before.state.skills()}
    new = {skill.id: skill for skill in after.state.skills()}
    edits: list[FieldChange] = []
    statuses: list[FieldChange] = []
    for skill_id in old.keys() & new.keys():
        edits += _compare(skill_id, _edit_fields(old[skill_id]), _edit_fields(new[skill_id]))
        statuses += _compare(skill_id, _status_fields(old[skill_id]), _status_fields(new[skill_id]))
    old_barriers = {b.id: " + ".join(b.skill_ids) for b in before.state.barriers}
    new_barriers = {b.id: " + ".join(b.skill_ids) for b in after.state.barriers}
    old_markers = {m.name: _marker_fields(m) for m in before.state.markers}
    new_markers = {m.name: _marker_fields(m) for m in after.state.markers}
    return MissionDiff(
        before,
        after,
        skills_added=_described(new, old, _skill_text),
        skills_removed=_described(old, new, _skill_text),
        edits=tuple(sorted(edits, key=_order)),
        statuses=tuple(sorted(statuses, key=_order)),
        barriers_added=_described(new_barriers, old_barriers, lambda i, v: f"{i}: {v}"),
        barriers_removed=_described(old_barriers, new_barriers, lambda i, v: f"{i}: {v}"),
        markers_added=_described(new_markers, old_markers, lambda n, v: f"{n} ({v['type']})"),
        markers_removed=_described(old_markers, new_markers, lambda n, v: f"{n} ({v['type']})"),
        marker_changes=tuple(
            change
            for name in sorted(old_markers.keys() & new_markers.keys())
            for change in _compare(name, old_markers[name], new_markers[name])
        ),
    )


def _order(change: FieldChange) -> tuple[str, str]:
    return change.subject, change.field


def _described(
    mine: Mapping[str, _T], other: Mapping[str, _T], describe: Callable[[str, _T], str]
) -> tuple[str, ...]:
    """The entries of ``mine`` that ``other`` lacks, described, in ``mine``'s order."""
    return tuple(describe(key, value) for key, value in mine.items() if key not in other)


def _skill_text(skill_id: str, skill: SkillInstance) -> str:
    return f"{skill_id} ({skill.agent} {skill.skill} '{skill.label}')"


def _compare(subject: str, old: Mapping[str, str], new: Mapping[str, str]) -> list[FieldChange]:
    """The fields whose values differ; a field only one side has shows as '-' on the other."""
    keys = list(old) + [key for key in new if key not in old]
    return [
        FieldChange(subject, key, old.get(key, "-"), new.get(key, "-"))
        for key in keys
        if old.get(key) != new.get(key)
    ]


def _edit_fields(skill: SkillInstance) -> dict[str, str]:
    fields = {
        "agent": skill.agent,
        "label": skill.label,
        "timeout": f"{skill.timeout:g}",
        "max_retries": str(skill.max_retries),
    }
    fields.update({f"param {name}": _value(v) for name, v in sorted(skill.params.items())})
    fields.update({f"binding {name}": f"@{m}" for name, m in sorted(skill.bindings.items())})
    return fields


def _status_fields(skill: SkillInstance) -> dict[str, str]:
    return {
        "status": skill.status.name,
        "transfer": skill.transfer.name,
        "resolution": skill.resolution.name,
        "attempt": str(skill.attempt),
    }


def _marker_fields(marker: TaskMarker) -> dict[str, str]:
    return {
        "type": marker.type.name,
        "pose": _value(marker.pose),
        "vertices": " ".join(f"({v.x:g}, {v.y:g})" for v in marker.vertices),
    }


def _value(value: object) -> str:
    """A parameter value as one short line (floats without trailing zeros)."""
    if isinstance(value, float):
        return f"{value:g}"
    fields = getattr(value, "__dataclass_fields__", None)
    if fields:
        inner = ", ".join(f"{name}={_value(getattr(value, name))}" for name in fields)
        return f"({inner})"
    return str(value)
