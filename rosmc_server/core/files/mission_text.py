"""Mission documents as text, written fast: one line per skill.

A mission file is YAML (see :mod:`.persistence`), but emitting and parsing YAML in Python
costs microseconds per value, which at 10,000 skills made saving and loading take
seconds. So each skill (and each barrier and task marker) is written as one line: a flow
mapping in JSON syntax, which YAML reads as the same mapping::

    tasks:
      drone:
      - {"id": "drone-1a2b", "skill": "take_off", "label": "take off", "params": {...}, ...}

:func:`flow_line` writes only what YAML reads identically (it declines data for which
JSON and YAML differ, and the entry is then written in YAML's block style), so a document
reads the same with any YAML reader. :func:`~.document_reading.read_document` reads such
lines with the C ``json`` module and only the few lines around them with the YAML parser.

:class:`MissionDumper` keeps each skill's line, keyed by the (immutable) skill instance,
so saving a large mission after a change writes only the changed skills afresh, and ends
the document with a digest of its text that lets the reader skip re-checking each line.
"""

from __future__ import annotations

import hashlib
import json
import re
import threading
from collections.abc import Mapping
from typing import Any

import yaml

from ..documents.documents import SafeDumper
from ..model.model import Barrier, Resolution, SkillInstance, SkillStatus, TaskMarker, Transfer
from ..model.state import MissionContent
from ..skills.params import value_to_data

MISSION_VERSION = 1

# Characters YAML reads otherwise than JSON inside a quoted string (line breaks YAML
# folds: NEL, LS, PS), or refuses in a stream (C1 controls, surrogates, BOM, non-characters).
_UNSAFE = re.compile("[\x7f-\x9f\u2028\u2029\ud800-\udfff\ufeff\ufffe\uffff]")
# The mantissa of a number with an exponent: without a fraction (JSON's 1e-05), YAML 1.1
# reads it as text. Text that merely looks like one makes the line decline too: safe.
_EXPONENT = re.compile(r"([\d.]+)e[-+]\d")
# YAML refuses an implicit key longer than 1024 characters; a line this long is checked.
_LONG_KEY = 1000


class _PlainDumper(SafeDumper):  # type: ignore[misc, valid-type]
    """A safe dumper that writes shared values out in full instead of as anchors and aliases.

    A retried skill shares its parameter values with the original; aliases would
    make the file harder to read and not come back identical after a load.
    """

    def ignore_aliases(self, data: Any) -> bool:
        return True


def yaml_block(data: Any) -> str:
    """``data`` in YAML's block style, as mission files have always been written."""
    return str(yaml.dump(data, Dumper=_PlainDumper, sort_keys=False, width=100))


# -- plain data ---------------------------------------------------------------------------
def mission_to_dict(content: MissionContent, revision: int) -> dict[str, Any]:
    """The mission as plain data, ready for ``yaml.safe_dump``."""
    return {
        "rosmc_mission": MISSION_VERSION,
        "library": content.library,
        "revision": revision,
        "tasks": {
            agent: [skill_to_dict(skill) for skill in task] for agent, task in content.tasks.items()
        },
        "barriers": [barrier_to_dict(b) for b in content.barriers.values()],
        "markers": [marker_to_dict(m) for m in content.markers.values()],
    }


def skill_to_dict(skill: SkillInstance) -> dict[str, Any]:
    """A skill as the plain data of a mission file (defaults left out)."""
    data: dict[str, Any] = {
        "id": skill.id,
        "skill": skill.skill,
        "label": skill.label,
        "params": {name: value_to_data(value) for name, value in skill.params.items()},
        "status": _STATUS_NAMES[skill.status],
    }
    if skill.bindings:
        data["bindings"] = dict(skill.bindings)
    # The optional fields, each only if it differs from its default (in this order).
    if skill.transfer is not Transfer.NONE:
        data["transfer"] = skill.transfer.name
    if skill.resolution is not Resolution.NONE:
        data["resolution"] = skill.resolution.name
    if skill.attempt != 1:
        data["attempt"] = skill.attempt
    if skill.timeout != 0.0:
        data["timeout"] = skill.timeout
    if skill.max_retries != 0:
        data["max_retries"] = skill.max_retries
    if skill.status_text != "":
        data["status_text"] = skill.status_text
    if skill.started != 0.0:
        data["started"] = skill.started
    if skill.finished != 0.0:
        data["finished"] = skill.finished
    return data


_STATUS_NAMES: Mapping[SkillStatus, str] = {status: status.name for status in SkillStatus}


def barrier_to_dict(barrier: Barrier) -> dict[str, Any]:
    """A barrier as the plain data of a mission file."""
    return {"id": barrier.id, "skills": list(barrier.skill_ids)}


def marker_to_dict(marker: TaskMarker) -> dict[str, Any]:
    """A task marker as the plain data of a mission file."""
    data: dict[str, Any] = {
        "name": marker.name,
        "type": marker.type.name,
        "pose": marker.pose.to_dict(),
    }
    if marker.vertices:
        data["vertices"] = [v.to_dict() for v in marker.vertices]
    return data


# -- one line per entry -----------------------------------------------------------------------
JSON_ENCODER = json.JSONEncoder(ensure_ascii=False)  # what flow lines are written with


def flow_line(data: dict[str, Any]) -> str | None:
    """``data`` as one line of JSON that YAML reads identically, or None if it cannot be.

    JSON strings, integers, floats with a fraction, true, false and null mean the same in
    YAML's flow style. Declined: characters YAML folds or refuses, floats JSON writes
    without a fraction (``1e-05``), and keys too long for YAML.
    """
    try:
        text = JSON_ENCODER.encode(data)
    except (TypeError, ValueError, RecursionError):
        return None
    return text if yaml_reads_alike(text, [text], [data]) else None


def yaml_reads_alike(text: str, lines: list[str], items: list[dict[str, Any]]) -> bool:
    """Whether YAML reads the JSON ``text`` of ``lines`` holding ``items`` as JSON does."""
    if _UNSAFE.search(text):
        return False
    if ("e-" in text or "e+" in text) and any(
        "." not in number for number in _EXPONENT.findall(text)
    ):
        return False
    return not any(
        len(line) > _LONG_KEY and _has_long_key(item)
        for line, item in zip(lines, items, strict=True)
    )


def _has_long_key(data: object) -> bool:
    pending = [data]
    while pending:
        item = pending.pop()
        if isinstance(item, dict):
            if any(len(JSON_ENCODER.encode(key)) > _LONG_KEY for key in item):
                return True
            pending.extend(item.values())
        elif isinstance(item, list):
            pending.extend(item)
    return False


def entry(data: dict[str, Any], indent: str) -> str:
    """One item of a block sequence at ``indent``: a flow line if possible, else YAML."""
    line = flow_line(data)
    if line is not None:
        return f"{indent}- {line}\n"
    return _indented(yaml_block([data]), indent)


def entries(items: list[dict[str, Any]], indent: str) -> list[str]:
    """:func:`entry` of each item, with YAML's reading of their JSON lines checked at once.

    One pass of the checks over all lines (almost always passed) instead of one per line.
    """
    try:
        texts = [JSON_ENCODER.encode(data) for data in items]
    except (TypeError, ValueError, RecursionError):
        return [entry(data, indent) for data in items]  # each tried on its own
    if yaml_reads_alike("\n".join(texts), texts, items):
        return [f"{indent}- {text}\n" for text in texts]
    return [entry(data, indent) for data in items]


def digest_line(text: str) -> str:
    """The comment a document ends with: the SHA-256 of its text before it.

    While it matches, the reader knows the text is as written and every flow line checked
    (see :mod:`.document_reading`); any edit only makes reading it take the full checks.
    """
    return f"# sha256 of the text above: {hashlib.sha256(text.encode()).hexdigest()}\n"


def _indented(block: str, indent: str) -> str:
    """YAML text shifted right by ``indent`` (split at newlines only: YAML escapes the rest)."""
    return "".join(f"{indent}{row}\n" for row in block.rstrip("\n").split("\n"))


# -- whole documents ---------------------------------------------------------------------------
class MissionDumper:
    """Writes mission documents, reusing the lines of skills unchanged since the last one.

    Skill instances are frozen and replaced on every change, so an instance still in the
    mission writes the line it wrote last time. Safe to use from several threads.
    """

    def __init__(self) -> None:
        self._lines: dict[int, tuple[SkillInstance, str]] = {}
        self._lock = threading.Lock()

    def dump(self, content: MissionContent, revision: int) -> str:
        """The mission as a YAML document, ending with its :func:`digest_line`."""
        with self._lock:
            previous = self._lines
        current: dict[int, tuple[SkillInstance, str]] = {}
        fresh: list[SkillInstance] = []
        for task in content.tasks.values():
            for skill in task:
                cached = previous.get(id(skill))
                if cached is not None and cached[0] is skill:  # ids are reused once freed
                    current[id(skill)] = cached
                else:
                    fresh.append(skill)
        lines = entries([skill_to_dict(skill) for skill in fresh], "  ")
        current.update((id(skill), (skill, line)) for skill, line in zip(fresh, lines, strict=True))
        head = {"rosmc_mission": MISSION_VERSION, "library": content.library, "revision": revision}
        parts = [yaml_block(head), "tasks:\n" if content.tasks else "tasks: {}\n"]
        for agent, task in content.tasks.items():
            key = _simple_key(agent)
            if key is None:  # written as YAML writes it
                parts.append(_indented(yaml_block({agent: [skill_to_dict(s) for s in task]}), "  "))
                continue
            parts.append(f"  {key}:\n" if task else f"  {key}: []\n")
            parts += [current[id(skill)][1] for skill in task]
        parts.append(_section("barriers", [barrier_to_dict(b) for b in content.barriers.values()]))
        parts.append(_section("markers", [marker_to_dict(m) for m in content.markers.values()]))
        with self._lock:
            self._lines = current
        text = "".join(parts)
        return text + digest_line(text)


def _simple_key(name: str) -> str | None:
    """A mapping key as YAML writes it on one line (quoted if need be), or None."""
    text = yaml_block({name: None})
    if not text.endswith(": null\n") or "\n" in text[: -len(": null\n")]:
        return None  # a very long key, which YAML writes as "? key"
    return text[: -len(": null\n")]


def _section(name: str, entries: list[dict[str, Any]]) -> str:
    if not entries:
        return f"{name}: []\n"
    return f"{name}:\n" + "".join(entry(data, "") for data in entries)
