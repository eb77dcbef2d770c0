"""Skill entries of a mission document in their usual form, checked a column at a time.

Most entries of a mission file have one form: the five keys ROSMC writes for a skill
whose optional fields are all at their defaults (``id``, ``skill``, ``label``, ``params``,
``status``, in this order). :func:`read_plain` checks a task of such entries field by
field over the whole task at once (one regular expression over all ids, one test of all
labels, each skill name and status once), leaving only the parameters and the building
of each skill to a loop. It accepts exactly what :class:`~.mission_reader._TaskReader`
accepts entry by entry, builds the same skills, and declines anything else: the task is
then read entry by entry, which says precisely what is wrong.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Iterable, Mapping
from operator import itemgetter
from typing import Any

from .errors import RosmcError
from .library import SkillSpec
from .model import NO_BINDINGS, Resolution, SkillInstance, SkillStatus, Transfer
from .params import Value
from .validation import MAX_ID, MAX_LABEL, has_control_characters

PLAIN_FORM = ("id", "skill", "label", "params", "status")
_FIELDS = itemgetter(*PLAIN_FORM)
# Ids one per line (an id holds no line break): the check_id of each, in one match.
_IDS = re.compile(r"[A-Za-z0-9][A-Za-z0-9_.:-]*(?:\n[A-Za-z0-9][A-Za-z0-9_.:-]*)*")
_STATUS: Mapping[str, SkillStatus] = SkillStatus.__members__
_assemble = SkillInstance.assemble

Spec = Callable[[str, str], SkillSpec]  # the library's skill of an agent
Params = Callable[[SkillSpec, dict[Any, Any]], "dict[str, Value] | None"]


def read_plain(
    entries: list[Any], agent: str, spec: Spec, params: Params
) -> list[SkillInstance] | None:
    """The skills of ``entries`` if each is a mapping of :data:`PLAIN_FORM` that passes
    every check, else None.

    ``spec`` and ``params`` are the task reader's (:meth:`~.mission_reader._TaskReader.spec`
    and :meth:`~.mission_reader._TaskReader.params`).
    """
    if not entries or set(map(type, entries)) != {dict}:
        return None
    if set(map(tuple, entries)) != {PLAIN_FORM}:
        return None
    rows = list(map(_FIELDS, entries))
    ids, names, labels, raw_params, statuses = zip(*rows, strict=True)
    if not (_all(str, ids) and _all(str, names) and _all(str, labels) and _all(str, statuses)):
        return None
    if not _all(dict, raw_params) or not _plain_ids(ids) or not _plain_labels(labels):
        return None
    status_of = {text: _STATUS[text] for text in set(statuses) if text in _STATUS}
    try:
        spec_of = {name: spec(agent, name) for name in set(names) if name.strip()}
    except RosmcError:
        return None
    if len(status_of) != len(set(statuses)) or len(spec_of) != len(set(names)):
        return None
    skills: list[SkillInstance] = []
    append = skills.append
    no_transfer, no_resolution = Transfer.NONE, Resolution.NONE
    try:
        for skill_id, name, label, raw, status in rows:
            found = spec_of[name]
            checked = params(found, raw)
            if checked is None:
                return None
            append(
                _assemble(
                    skill_id, agent, found.name, label, checked, NO_BINDINGS,
                    status_of[status], no_transfer, no_resolution,
                    1, 0.0, 0, "", 0.0, 0.0,
                )
            )  # fmt: skip
    except RosmcError:
        return None
    return skills


def _all(kind: type, values: Iterable[object]) -> bool:
    """Whether every value is of exactly type ``kind``."""
    return set(map(type, values)) <= {kind}


def _plain_ids(ids: tuple[str, ...]) -> bool:
    """Whether each id passes :func:`~.validation.check_id`."""
    lines = "\n".join(ids)  # as many lines as ids: no id holds a line break itself
    return (
        max(map(len, ids)) <= MAX_ID
        and lines.count("\n") == len(ids) - 1
        and _IDS.fullmatch(lines) is not None
    )


def _plain_labels(labels: tuple[str, ...]) -> bool:
    """Whether each label passes :func:`~.editing.check_label` (no default): one line, not
    blank, at most MAX_LABEL long (a label that passes only once stripped is declined)."""
    return (
        max(map(len, labels)) <= MAX_LABEL
        and all(map(str.strip, labels))
        and ("".join(labels).isprintable() or not any(map(has_control_characters, labels)))
    )
