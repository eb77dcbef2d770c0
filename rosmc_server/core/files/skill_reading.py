"""Reading one skill entry of a mission document, quickly or precisely.

Part of :mod:`.mission_reader`. A well-formed skill entry is read on a quick path (the
same checks, run directly, without composing key paths); any entry the quick path does
not accept is read again with the :class:`~.documents.DocumentReader`, which either
builds the same skill or says precisely what is wrong.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import replace
from typing import Any

from ..documents.documents import DocumentReader
from ..errors import MissionFileError, RosmcError
from ..model.model import Resolution, SkillInstance, SkillStatus, TaskMarker, Transfer
from ..rules.editing import bound_values, check_label, check_params, check_retries, check_timeout
from ..skills.library import Library, ParameterSpec, SkillSpec
from ..skills.params import QuickCheck, Value, quick_checker
from ..validation import (
    MAX_ATTEMPT,
    MAX_STATUS_TEXT,
    check_id,
    check_one_line,
    check_time,
    check_whole,
)

_REQUIRED = frozenset({"id", "skill", "params"})
_OPTIONAL = frozenset(
    {
        "label",
        "bindings",
        "status",
        "transfer",
        "resolution",
        "attempt",
        "timeout",
        "max_retries",
        "status_text",
        "started",
        "finished",
    }
)
_KEYS = _REQUIRED | _OPTIONAL
_STATUS: Mapping[str, SkillStatus] = SkillStatus.__members__
_TRANSFER: Mapping[str, Transfer] = Transfer.__members__
_RESOLUTION: Mapping[str, Resolution] = Resolution.__members__


class TaskReader:
    """Reads the skills of one document, remembering the library's answers."""

    def __init__(
        self, reader: DocumentReader, library: Library, markers: Mapping[str, TaskMarker]
    ) -> None:
        self.reader = reader
        self.library = library
        self.markers = markers
        self._specs: dict[tuple[str, str], SkillSpec] = {}
        # by id(spec): each parameter with its quick check
        self._parameters: dict[int, dict[str, tuple[ParameterSpec, QuickCheck]]] = {}

    def marker(self, name: str) -> TaskMarker:
        """The marker ``name`` of the document."""
        if name not in self.markers:
            raise MissionFileError(f"binds marker {name!r}, which the file does not define")
        return self.markers[name]

    def spec(self, agent: str, skill: str) -> SkillSpec:
        """The library's skill ``skill`` of ``agent`` (NotFound, RuleViolation)."""
        found = self._specs.get((agent, skill))
        if found is None:
            found = self._specs[(agent, skill)] = self.library.skill(agent, skill)
        return found

    def quick(self, raw: object, agent: str) -> SkillInstance | None:
        """The skill a well-formed entry holds, or None (then :meth:`precise` says why).

        The same checks as :meth:`precise`, called directly; a field the entry leaves out
        takes its default without a check.
        """
        if type(raw) is not dict or not _REQUIRED <= raw.keys() <= _KEYS:
            return None
        name, params, bindings = raw["skill"], raw["params"], raw.get("bindings", {})
        label: object = raw.get("label", name)
        status_text: object = raw.get("status_text", "")
        status = _enum(_STATUS, raw["status"]) if "status" in raw else SkillStatus.IDLE
        transfer = _enum(_TRANSFER, raw["transfer"]) if "transfer" in raw else Transfer.NONE
        resolution = (
            _enum(_RESOLUTION, raw["resolution"]) if "resolution" in raw else Resolution.NONE
        )
        if (
            type(name) is not str
            or not name.strip()
            or not isinstance(label, str)
            or not isinstance(status_text, str)
            or type(params) is not dict
            or type(bindings) is not dict
            or status is None
            or transfer is None
            or resolution is None
            or (bindings and not all(type(m) is str and m.strip() for m in bindings.values()))
        ):
            return None
        try:
            check_label(label, None)
            if status_text:
                check_one_line(status_text, "a status text", MAX_STATUS_TEXT, empty=True)
            spec = self.spec(agent, name)
            checked = self.params(spec, params)
            if checked is None:
                return None
            if bindings:
                bound_values(self.marker, spec, bindings)
            return SkillInstance.assemble(
                check_id(raw["id"]),
                agent,
                spec.name,
                label,
                checked,
                dict(bindings),
                status,
                transfer,
                resolution,
                # The optional fields: absent from most entries, then their defaults.
                check_whole(raw["attempt"], "an attempt", 1, MAX_ATTEMPT)
                if "attempt" in raw
                else 1,
                check_timeout(raw["timeout"]) if "timeout" in raw else 0.0,
                check_retries(raw["max_retries"]) if "max_retries" in raw else 0,
                status_text,
                check_time(raw["started"], "a start time") if "started" in raw else 0.0,
                check_time(raw["finished"], "a finish time") if "finished" in raw else 0.0,
            )
        except RosmcError:
            return None

    def params(self, spec: SkillSpec, raw: dict[Any, Any]) -> dict[str, Value] | None:
        """Every parameter of ``spec`` checked (as :func:`~.editing.check_params` checks
        them), or None if one is unknown or missing; RosmcError if a value is wrong."""
        by_name = self._parameters.get(id(spec))  # the library keeps its specs alive
        if by_name is None:
            by_name = self._parameters[id(spec)] = {
                p.name: (p, quick_checker(p.type, p.minimum, p.maximum, p.choices))
                for p in spec.parameters
            }
        if len(raw) != len(by_name):
            return None
        checked: dict[str, Value] = {}
        for name, value in raw.items():
            found = by_name.get(name)
            if found is None:
                return None
            param, quick_check = found
            quick = quick_check(value)
            # Keyed by the library's name: one string shared by every skill, not one each.
            checked[param.name] = param.check(value, spec.name) if quick is None else quick
        return checked

    def precise(self, raw: object, agent: str, key: str, seen: set[str]) -> SkillInstance:
        """The skill an entry holds, or MissionFileError saying what is wrong and where."""
        reader = self.reader
        skill = _read_skill(reader, raw, agent, key)
        try:
            check_loaded_skill(skill)
        except RosmcError as error:
            reader.fail(key, str(error))
        if skill.id in seen:
            reader.fail(f"{key}.id", f"skill id {skill.id!r} appears twice")
        try:
            spec = self.spec(agent, skill.skill)
            checked = check_params(spec, skill.params)
            bound_values(self.marker, spec, skill.bindings)
        except RosmcError as error:
            reader.fail(key, str(error))
        missing = sorted({p.name for p in spec.parameters} - set(checked))
        if missing:
            reader.fail(f"{key}.params", f"is missing {', '.join(missing)}")
        return replace(skill, params=checked)


def _enum(members: Mapping[str, Any], raw: object) -> Any:
    return members.get(raw) if isinstance(raw, str) else None


def check_loaded_skill(skill: SkillInstance) -> None:
    """The checks an added or edited skill passes, for a skill read from a file."""
    check_id(skill.id)
    check_label(skill.label, None)
    check_timeout(skill.timeout)
    check_retries(skill.max_retries)
    check_whole(skill.attempt, "an attempt", 1, MAX_ATTEMPT)
    check_one_line(skill.status_text, "a status text", MAX_STATUS_TEXT, empty=True)


def _read_skill(reader: DocumentReader, raw: object, agent: str, key: str) -> SkillInstance:
    body = reader.mapping(raw, key, set(_REQUIRED), set(_OPTIONAL))
    params = reader.mapping(body["params"], f"{key}.params", set(), None)
    bindings = reader.mapping(body.get("bindings", {}), f"{key}.bindings", set(), None)
    for name, marker in bindings.items():
        reader.text(marker, f"{key}.bindings.{name}")
    return SkillInstance(
        id=reader.text(body["id"], f"{key}.id"),
        agent=agent,
        skill=reader.text(body["skill"], f"{key}.skill"),
        label=reader.text(body.get("label", body["skill"]), f"{key}.label"),
        params=dict(params),
        bindings=dict(bindings),
        status=reader.enum(SkillStatus, body.get("status", "IDLE"), f"{key}.status"),
        transfer=reader.enum(Transfer, body.get("transfer", "NONE"), f"{key}.transfer"),
        resolution=reader.enum(Resolution, body.get("resolution", "NONE"), f"{key}.resolution"),
        attempt=reader.whole(body.get("attempt", 1), f"{key}.attempt", minimum=1),
        timeout=reader.number(body.get("timeout", 0.0), f"{key}.timeout", minimum=0.0),
        max_retries=reader.whole(body.get("max_retries", 0), f"{key}.max_retries", minimum=0),
        status_text=reader.text(body.get("status_text", ""), f"{key}.status_text", empty=True),
        started=reader.number(body.get("started", 0.0), f"{key}.started", minimum=0.0),
        finished=reader.number(body.get("finished", 0.0), f"{key}.finished", minimum=0.0),
    )
