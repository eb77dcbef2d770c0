"""Mission documents as text, written and read fast: one line per skill.

A mission file is YAML (see :mod:`.persistence`), but emitting and parsing YAML in Python
costs microseconds per value, which at 10,000 skills made saving and loading take
seconds. So each skill (and each barrier and task marker) is written as one line: a flow
mapping in JSON syntax, which YAML reads as the same mapping::

    tasks:
      drone:
      - {"id": "drone-1a2b", "skill": "take_off", "label": "take off", "params": {...}, ...}

:func:`read_document` reads such lines with the C ``json`` module and only the few lines
around them with the YAML parser. A line is read as JSON only if it is exactly what
:func:`flow_line` writes for the data it holds, and :func:`flow_line` writes only what
YAML reads identically (it declines data for which JSON and YAML differ, and the entry is
then written in YAML's block style), so a document reads the same either way: edited by
hand, written by another tool or by an older ROSMC.

:class:`MissionDumper` keeps each skill's line, keyed by the (immutable) skill instance,
so saving a large mission after a change writes only the changed skills afresh.
"""

from __future__ import annotations

import json
import re
import secrets
import threading
from collections.abc import Mapping
from json.scanner import make_scanner
from typing import Any

import yaml

from .documents import SafeDumper, load_yaml
from .errors import MissionFileError
from .model import Barrier, SkillInstance, TaskMarker
from .params import value_to_data
from .state import MissionContent

MISSION_VERSION = 1

# Characters YAML reads otherwise than JSON inside a quoted string (line breaks YAML
# folds: NEL, LS, PS), or refuses in a stream (C1 controls, surrogates, BOM, non-characters).
_UNSAFE = re.compile("[\x7f-\x9f\u2028\u2029\ud800-\udfff\ufeff\ufffe\uffff]")
# The mantissa of a number with an exponent: without a fraction (JSON's 1e-05), YAML 1.1
# reads it as text. Text that merely looks like one makes the line decline too: safe.
_EXPONENT = re.compile(r"([\d.]+)e[-+]\d")
# YAML refuses an implicit key longer than 1024 characters; a line this long is checked.
_LONG_KEY = 1000
# One entry of a block sequence, written as a one-line flow mapping.
_FLOW_ENTRY = re.compile(r"^( *)- (\{.*\})$", re.MULTILINE)


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
        "status": skill.status.name,
    }
    if skill.bindings:
        data["bindings"] = dict(skill.bindings)
    optional = {
        "transfer": (skill.transfer.name, "NONE"),
        "resolution": (skill.resolution.name, "NONE"),
        "attempt": (skill.attempt, 1),
        "timeout": (skill.timeout, 0.0),
        "max_retries": (skill.max_retries, 0),
        "status_text": (skill.status_text, ""),
        "started": (skill.started, 0.0),
        "finished": (skill.finished, 0.0),
    }
    data.update({key: value for key, (value, default) in optional.items() if value != default})
    return data


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
def _refuse_constant(name: str) -> None:
    raise ValueError(f"{name} is not a YAML number")  # NaN and Infinity are text in YAML


_ENCODER = json.JSONEncoder(ensure_ascii=False)
# The C scanner json.loads runs, called directly (one line is one call). typeshed's stub
# wants the scanner's own type for its context; a decoder has every attribute it reads.
_SCAN = make_scanner(json.JSONDecoder(parse_constant=_refuse_constant))  # type: ignore[arg-type]


def flow_line(data: dict[str, Any]) -> str | None:
    """``data`` as one line of JSON that YAML reads identically, or None if it cannot be.

    JSON strings, integers, floats with a fraction, true, false and null mean the same in
    YAML's flow style. Declined: characters YAML folds or refuses, floats JSON writes
    without a fraction (``1e-05``), and keys too long for YAML.
    """
    try:
        text = _ENCODER.encode(data)
    except (TypeError, ValueError, RecursionError):
        return None
    return text if _yaml_reads_alike(text, [text], [data]) else None


def _yaml_reads_alike(text: str, lines: list[str], items: list[dict[str, Any]]) -> bool:
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
            if any(len(_ENCODER.encode(key)) > _LONG_KEY for key in item):
                return True
            pending.extend(item.values())
        elif isinstance(item, list):
            pending.extend(item)
    return False


def _scan_line(text: str) -> dict[str, Any] | None:
    """The mapping a line of JSON holds (exactly one value, nothing after it), or None."""
    try:
        data, end = _SCAN(text, 0)
    except (StopIteration, ValueError, RecursionError):
        return None
    return data if end == len(text) and type(data) is dict else None


def _written_alike(lines: list[str], items: list[dict[str, Any]]) -> bool:
    """Whether each line is exactly what :func:`flow_line` writes for its item.

    One encoding of the whole run: each line holds exactly its item, so if the joined
    texts are equal, each line equals its item's encoding (neither of two texts of one
    complete JSON value can be a proper prefix of the other).
    """
    try:
        text = _ENCODER.encode(items)
    except (TypeError, ValueError, RecursionError):
        return False
    return text == f"[{', '.join(lines)}]" and _yaml_reads_alike(text, lines, items)


def entry(data: dict[str, Any], indent: str) -> str:
    """One item of a block sequence at ``indent``: a flow line if possible, else YAML."""
    line = flow_line(data)
    if line is not None:
        return f"{indent}- {line}\n"
    return _indented(yaml_block([data]), indent)


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
        """The mission as a YAML document."""
        with self._lock:
            previous = self._lines
        current: dict[int, tuple[SkillInstance, str]] = {}
        head = {"rosmc_mission": MISSION_VERSION, "library": content.library, "revision": revision}
        parts = [yaml_block(head), "tasks:\n" if content.tasks else "tasks: {}\n"]
        for agent, task in content.tasks.items():
            key = _simple_key(agent)
            if key is None:  # written as YAML writes it
                parts.append(_indented(yaml_block({agent: [skill_to_dict(s) for s in task]}), "  "))
                continue
            parts.append(f"  {key}:\n" if task else f"  {key}: []\n")
            for skill in task:
                cached = previous.get(id(skill))
                if cached is None or cached[0] is not skill:  # ids are reused once freed
                    cached = (skill, entry(skill_to_dict(skill), "  "))
                current[id(skill)] = cached
                parts.append(cached[1])
        parts.append(_section("barriers", [barrier_to_dict(b) for b in content.barriers.values()]))
        parts.append(_section("markers", [marker_to_dict(m) for m in content.markers.values()]))
        with self._lock:
            self._lines = current
        return "".join(parts)


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


def read_document(text: str, source: str) -> Any:
    """Parse a mission document as YAML does, reading flow-line entries with ``json``.

    Each run of consecutive flow lines (at one indentation) that is exactly what
    :func:`flow_line` writes is replaced by one placeholder item (a random token nobody
    can guess), the rest is parsed as YAML, and each placeholder is replaced by its run's
    entries. If a placeholder is missing or stands where no list item could, the whole
    text is parsed as YAML instead.

    Raises:
        yaml.YAMLError: What :func:`~.documents.load_yaml` raises for the text.
        MissionFileError: YAML aliases expand the document beyond reason.
    """
    runs: list[tuple[int, int, str, list[str], list[dict[str, Any]]]] = []
    for match in _FLOW_ENTRY.finditer(text):
        data = _scan_line(match.group(2))
        if data is None:
            continue
        indent = match.group(1)
        if runs and runs[-1][1] + 1 == match.start() and runs[-1][2] == indent:
            start, _, _, lines, items = runs[-1]
            runs[-1] = (start, match.end(), indent, lines, items)
        else:
            runs.append((match.start(), match.end(), indent, [], []))
        runs[-1][3].append(match.group(2))
        runs[-1][4].append(data)
    token = secrets.token_hex(12)
    kept: list[list[dict[str, Any]]] = []
    weights: dict[str, int] = {}  # a placeholder stands for at most this many values
    pieces: list[str] = []
    done = 0
    for start, end, indent, lines, items in runs:
        if _written_alike(lines, items):
            placeholder = f"{token}:{len(kept)}"
            pieces += [text[done:start], f'{indent}- "{placeholder}"']
            weights[placeholder] = end - start
            kept.append(items)
            done = end
    if kept:
        pieces.append(text[done:])
        try:
            data = load_yaml("".join(pieces))
        except yaml.YAMLError:
            data = None  # the error as the document itself shows it, below
        if data is not None:
            refuse_alias_bombs(data, len(text), source, weights)
            if _put_back(data, f"{token}:", kept):
                return data
    data = load_yaml(text)
    refuse_alias_bombs(data, len(text), source)
    return data


def refuse_alias_bombs(
    data: object, length: int, source: str, weights: Mapping[str, int] | None = None
) -> None:
    """Refuse a document whose YAML aliases expand it far beyond its own size.

    An alias refers to a value written once, but checking copies it wherever it
    is used, so a few hundred bytes of nested aliases ("billion laughs") would
    take hours to load. Ordinary sharing (what yaml.safe_dump writes for repeated
    values) stays well within the allowance. A string of ``weights`` counts as that
    many values (a placeholder for entries read apart).
    """
    allowance = 100_000 + 20 * length
    weigh = (weights or {}).get
    pending, count = [data], 0
    while pending:
        item = pending.pop()
        count += weigh(item, 1) if isinstance(item, str) else 1
        if count > allowance:
            raise MissionFileError(
                f"{source}: its YAML aliases expand it to more than {allowance} values"
            )
        if isinstance(item, dict):
            pending.extend(item.values())
        elif isinstance(item, list):
            pending.extend(item)


def _put_back(data: Any, prefix: str, runs: list[list[dict[str, Any]]]) -> bool:
    """Replace each placeholder item of a list by its run; whether each was found once.

    A placeholder anywhere but as a list item (a key, a mapping value) counts as missing.
    """
    found: set[int] = set()
    pending, seen = [data], set()
    while pending:
        item = pending.pop()
        if id(item) in seen:  # a YAML alias shares one list between places
            continue
        seen.add(id(item))
        values = list(item.values()) if isinstance(item, dict) else item
        expanded: list[Any] = []
        replaced = False
        for value in values:
            if isinstance(value, str) and value.startswith(prefix):
                number = int(value[len(prefix) :]) if value[len(prefix) :].isdigit() else -1
                if not isinstance(item, list) or not 0 <= number < len(runs) or number in found:
                    return False
                found.add(number)
                expanded.extend(runs[number])
                replaced = True
                continue
            expanded.append(value)
            if isinstance(value, (dict, list)):
                pending.append(value)
        if replaced:
            item[:] = expanded  # only lists get here
    return len(found) == len(runs)
