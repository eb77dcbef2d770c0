"""Skill entries of a mission document in their usual form, checked a column at a time.

Most entries of a mission file have one form: the five keys ROSMC writes for a skill
whose optional fields are all at their defaults (``id``, ``skill``, ``label``, ``params``,
``status``, in this order). :func:`read_plain` checks a task of such entries field by
field over the whole task at once (one regular expression over all ids, one test of all
labels, each skill name and status once), leaving only the parameters and the building
of each skill to a loop. It accepts exactly what :class:`~.skill_reading.TaskReader`
accepts entry by entry, builds the same skills, and declines anything else: the task is
then read entry by entry, which says precisely what is wrong.
"""

from __future__ import annotations

import json
import re
from collections.abc import Callable, Iterable, Mapping
from operator import itemgetter
from typing import Any, cast

from ..errors import RosmcError
from ..model.model import NO_BINDINGS, Resolution, SkillInstance, SkillStatus, Transfer
from ..skills.library import SkillSpec
from ..skills.params import Value
from ..validation import MAX_ID, MAX_LABEL, has_control_characters

PLAIN_FORM = ("id", "skill", "label", "params", "status")
_FIELDS = itemgetter(*PLAIN_FORM)
# Ids one per line (an id holds no line break): the check_id of each, in one match.
_IDS = re.compile(r"[A-Za-z0-9][A-Za-z0-9_.:-]*(?:\n[A-Za-z0-9][A-Za-z0-9_.:-]*)*")
_STATUS: Mapping[str, SkillStatus] = SkillStatus.__members__
_assemble = SkillInstance.assemble

Spec = Callable[[str, str], SkillSpec]  # the library's skill of an agent
Params = Callable[[SkillSpec, dict[Any, Any]], "dict[str, Value] | None"]


class PlainTask:
    """The entries of a task that ROSMC wrote, each one line of :data:`PLAIN_FORM`, as the
    text of their fields: read without a mapping per entry (see :func:`read_plain_task`).

    Made by :func:`~.document_reading.read_document` for a document that ends with its
    writer's digest; ``params`` holds each distinct parameters text read once.
    """

    __slots__ = ("params", "rows")

    def __init__(self, rows: list[tuple[str, str, str, str, str]], params: dict[str, Any]):
        self.rows = rows
        self.params = params

    def __len__(self) -> int:
        return len(self.rows)

    def entries(self) -> list[dict[str, Any]]:
        """The mapping of each entry, as YAML (and ``json``) reads its line."""
        # Each parameters text is one complete JSON mapping (the document reader scanned
        # it), so a line reads as its fields; each entry gets its own parameters.
        return [
            dict(zip(PLAIN_FORM, (i, skill, label, json.loads(params), status), strict=True))
            for i, skill, label, params, status in self.rows
        ]

    def clear(self) -> None:
        """Let go of the entries (they have been read)."""
        self.rows = []
        self.params = {}


def read_plain(
    entries: list[Any], agent: str, spec: Spec, params: Params
) -> list[SkillInstance] | None:
    """The skills of ``entries`` if each is a mapping of :data:`PLAIN_FORM` that passes
    every check, else None.

    ``spec`` and ``params`` are the task reader's (:meth:`~.skill_reading.TaskReader.spec`
    and :meth:`~.skill_reading.TaskReader.params`).
    """
    if not entries or set(map(type, entries)) != {dict}:
        return None
    if set(map(tuple, entries)) != {PLAIN_FORM}:
        return None
    ids, names, labels, raw_params, statuses = zip(*map(_FIELDS, entries), strict=True)
    if not (_all(str, ids) and _all(str, names) and _all(str, labels) and _all(str, statuses)):
        return None
    if not _all(dict, raw_params):
        return None
    checked = _checked_columns(ids, names, labels, statuses, agent, spec)
    if checked is None:
        return None
    spec_of, status_of = checked
    try:
        column = [params(spec_of[name], raw) for name, raw in zip(names, raw_params, strict=True)]
    except RosmcError:
        return None
    return _build(agent, ids, names, labels, column, statuses, spec_of, status_of)


def read_plain_task(
    task: PlainTask, agent: str, spec: Spec, params: Params
) -> list[SkillInstance] | None:
    """The skills of ``task`` if each entry passes every check, else None (as
    :func:`read_plain` for the same entries). Alike parameters (the same text for the
    same skill) are checked once and share one dict (skills are immutable)."""
    if not task.rows:
        return None
    ids, names, labels, texts, statuses = zip(*task.rows, strict=True)
    checked = _checked_columns(ids, names, labels, statuses, agent, spec)
    if checked is None:
        return None
    spec_of, status_of = checked
    pairs = list(zip(names, texts, strict=True))
    raw_of = task.params
    try:
        alike = {pair: params(spec_of[pair[0]], raw_of[pair[1]]) for pair in set(pairs)}
    except RosmcError:
        return None
    column = list(map(alike.__getitem__, pairs))
    return _build(agent, ids, names, labels, column, statuses, spec_of, status_of)


def _checked_columns(
    ids: tuple[str, ...],
    names: tuple[str, ...],
    labels: tuple[str, ...],
    statuses: tuple[str, ...],
    agent: str,
    spec: Spec,
) -> tuple[dict[str, SkillSpec], dict[str, SkillStatus]] | None:
    """Each skill name's spec and each status text's status, if every id, label, name and
    status of the text columns passes its check, else None."""
    if not _plain_ids(ids) or not _plain_labels(labels):
        return None
    status_of = {text: _STATUS[text] for text in set(statuses) if text in _STATUS}
    try:
        spec_of = {name: spec(agent, name) for name in set(names) if name.strip()}
    except RosmcError:
        return None
    if len(status_of) != len(set(statuses)) or len(spec_of) != len(set(names)):
        return None
    return spec_of, status_of


def _build(
    agent: str,
    ids: tuple[str, ...],
    names: tuple[str, ...],
    labels: tuple[str, ...],
    params: list[dict[str, Value] | None],
    statuses: tuple[str, ...],
    spec_of: Mapping[str, SkillSpec],
    status_of: Mapping[str, SkillStatus],
) -> list[SkillInstance] | None:
    """The skills of checked columns (None if a parameters check declined)."""
    if None in params:
        return None
    checked_params = cast(list[dict[str, Value]], params)
    no_transfer, no_resolution = Transfer.NONE, Resolution.NONE
    return [
        _assemble(
            skill_id, agent, spec_of[name].name, label, checked, NO_BINDINGS,
            status_of[status], no_transfer, no_resolution, 1, 0.0, 0, "", 0.0, 0.0,
        )
        for skill_id, name, label, checked, status in zip(
            ids, names, labels, checked_params, statuses, strict=True
        )
    ]  # fmt: skip


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
