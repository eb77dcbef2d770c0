"""Mission documents read fast: flow-line entries with ``json``, the rest with YAML.

The reverse of :class:`~.mission_text.MissionDumper` (see :mod:`.mission_text` for the
format). :func:`read_document` reads a document exactly as YAML would, but the thousands
of one-line skill entries with the C ``json`` module.

A line is read as JSON only if it is exactly what :func:`~.mission_text.flow_line` writes
for the data it holds, which YAML reads identically. Checking that costs a JSON encoding
of each run of such lines and a search of it for what YAML reads otherwise; a document
that ends with the digest its writer appends (:func:`~.mission_text.digest_line`), still
matching its text, is as the writer wrote it, each line checked when it was written, so
the lines that each hold one JSON mapping are taken as they read. Any edit makes the
digest stale, and the document is then read with every check, as one from another tool
or an older ROSMC.
"""

from __future__ import annotations

import json
import re
import secrets
from collections.abc import Mapping
from dataclasses import dataclass, field
from json.scanner import make_scanner
from typing import Any

import yaml

from ..documents.documents import read_yaml
from ..errors import MissionFileError
from .mission_text import JSON_ENCODER, digest_line, yaml_reads_alike
from .plain_skills import PlainTask

# Consecutive entries of a block sequence at one indentation, each a one-line flow mapping.
_FLOW_RUN = re.compile(r"^( *)- \{.*\}$(?:\n\1- \{.*\}$)*", re.MULTILINE)
# The digest a document ends with (see mission_text.digest_line).
_DIGEST = re.compile(r"^# sha256 of the text above: [0-9a-f]{64}\n\Z", re.MULTILINE)
# A flow line of a skill in the plain form (plain_skills.PLAIN_FORM) whose strings hold no
# escape (nor a control character, which JSON refuses): each string is its text, and the
# parameters are the text between their key and the status (scanned apart).
_TEXT = r'"([^"\\\x00-\x1f]*)"'
_PLAIN_LINE = re.compile(
    rf'^ *- \{{"id": {_TEXT}, "skill": {_TEXT}, "label": {_TEXT}, "params": (\{{.*\}}), '
    rf'"status": {_TEXT}\}}$',
    re.MULTILINE,
)


def _refuse_constant(name: str) -> None:
    raise ValueError(f"{name} is not a YAML number")  # NaN and Infinity are text in YAML


# The C scanner json.loads runs, called directly (one line is one call). typeshed's stub
# wants the scanner's own type for its context; a decoder has every attribute it reads.
_SCAN = make_scanner(json.JSONDecoder(parse_constant=_refuse_constant))  # type: ignore[arg-type]


@dataclass
class _Run:
    """Consecutive flow lines at one indentation: where they stand and what they hold."""

    start: int
    end: int
    indent: str
    items: list[dict[str, Any]] = field(default_factory=list)
    plain: PlainTask | None = None  # the entries as text (then ``items`` is empty)

    def lines(self, text: str) -> list[str]:
        """Each line of the run in ``text`` without its indentation and ``- ``."""
        skip = len(self.indent) + 2
        return [line[skip:] for line in text[self.start : self.end].split("\n")]


def read_document(text: str, source: str, *, plain_tasks: bool = False) -> Any:
    """Parse a mission document as YAML does, reading flow-line entries with ``json``.

    Each run of consecutive flow lines (at one indentation) that is exactly what
    :func:`~.mission_text.flow_line` writes is replaced by one placeholder item (a random
    token nobody can guess), the rest is parsed as YAML, and each placeholder is replaced
    by its run's entries. If a placeholder is missing or stands where no list item could,
    the whole text is parsed as YAML instead.

    With ``plain_tasks``, a task (``tasks.<agent>``) of a document as its writer wrote it
    whose entries are all one run of lines in the plain form comes as a
    :class:`~.plain_skills.PlainTask` (its fields as text) instead of a list of mappings.

    Raises:
        yaml.YAMLError: What :func:`~.documents.load_yaml` raises for the text.
        MissionFileError: YAML aliases expand the document beyond reason.
    """
    as_written = _digest_matches(text)  # first: its copies of the text go before the entries come
    runs = _checked_runs(text, plain_tasks and as_written)
    if not as_written:
        runs = [run for run in runs if _written_alike(run.lines(text), run.items)]
    if runs:
        data = _read_around(text, source, runs)
        if data is not None:
            return data
    data, shared = read_yaml(text)
    if shared:  # without aliases, the data holds fewer values than the text has characters
        refuse_alias_bombs(data, len(text), source)
    return data


def _digest_matches(text: str) -> bool:
    """Whether ``text`` ends with the digest of the text before it (written, not edited)."""
    digest = _DIGEST.search(text, max(0, len(text) - 200))
    return digest is not None and digest_line(text[: digest.start()]) == digest.group()


def _checked_runs(text: str, plain: bool) -> list[_Run]:
    """The runs of lines that each hold one JSON mapping, read line by line (with
    ``plain``, a run of skills in the plain form is read as text, see :func:`_plain_task`)."""
    runs: list[_Run] = []
    for match in _FLOW_RUN.finditer(text):
        run = _Run(match.start(), match.end(), match.group(1))
        run.plain = _plain_task(text, run) if plain else None
        if run.plain is not None:
            runs.append(run)
            continue
        items = _read_lines(text, run)
        if items is not None:
            run.items = items
            runs.append(run)
        else:
            runs += _line_by_line(run.start, run.indent, run.lines(text))
    return runs


def _read_lines(text: str, run: _Run) -> list[dict[str, Any]] | None:
    """The mapping each line of ``run`` holds, or None if one does not hold exactly one.

    Each line is scanned where it stands in ``text`` (no copy of the run or its lines). A
    value that ends anywhere but at its line's end (before it, or on a later line: lines
    end with ``}``, after which JSON takes no value) declines the run, as a scan of the
    line alone would.
    """
    scan, find, end = _SCAN, text.find, run.end
    skip = len(run.indent) + 2  # the indentation and "- "
    items: list[dict[str, Any]] = []
    append = items.append
    at = run.start
    try:
        while at < end:
            stop = find("\n", at, end)
            stop = end if stop < 0 else stop
            item, after = scan(text, at + skip)
            if after != stop or type(item) is not dict:
                return None
            append(item)
            at = stop + 1
    except (StopIteration, ValueError, RecursionError):
        return None
    return items


def _plain_task(text: str, run: _Run) -> PlainTask | None:
    """The entries of ``run`` as text if each line is a skill in the plain form, else None.

    Each parameters text (each distinct one once) must be exactly one JSON mapping; the
    line is then exactly the mapping of its fields (JSON reads a value alone as it reads
    it inside the line), so no line is read whole.
    """
    rows = _PLAIN_LINE.findall(text, run.start, run.end)
    if len(rows) != text.count("\n", run.start, run.end) + 1:
        return None
    params: dict[str, Any] = {}
    try:
        for params_text in {row[3] for row in rows}:
            value, end = _SCAN(params_text, 0)
            if end != len(params_text) or type(value) is not dict:
                return None
            params[params_text] = value
    except (StopIteration, ValueError, RecursionError):
        return None
    return PlainTask(rows, params)


def _line_by_line(start: int, indent: str, lines: list[str]) -> list[_Run]:
    """The runs of ``lines`` (the first starting at ``start``) read one line at a time."""
    runs: list[_Run] = []
    at = start
    for line in lines:
        end = at + len(indent) + 2 + len(line)
        data = _scan_line(line)
        if data is not None:
            if runs and runs[-1].end + 1 == at:
                runs[-1].end = end
            else:
                runs.append(_Run(at, end, indent))
            runs[-1].items.append(data)
        at = end + 1
    return runs


def _scan_line(text: str) -> dict[str, Any] | None:
    """The mapping a line of JSON holds (exactly one value, nothing after it), or None."""
    try:
        data, end = _SCAN(text, 0)
    except (StopIteration, ValueError, RecursionError):
        return None
    return data if end == len(text) and type(data) is dict else None


def _written_alike(lines: list[str], items: list[dict[str, Any]]) -> bool:
    """Whether each line is exactly what :func:`~.mission_text.flow_line` writes for its item.

    One encoding of the whole run: each line holds exactly its item, so if the joined
    texts are equal, each line equals its item's encoding (neither of two texts of one
    complete JSON value can be a proper prefix of the other).
    """
    try:
        text = JSON_ENCODER.encode(items)
    except (TypeError, ValueError, RecursionError):
        return False
    return text == f"[{', '.join(lines)}]" and yaml_reads_alike(text, lines, items)


def _read_around(text: str, source: str, runs: list[_Run]) -> Any:
    """The document with each run read apart and put back, or None if one is not a list item."""
    token = secrets.token_hex(12)
    weights: dict[str, int] = {}  # a placeholder stands for at most this many values
    pieces: list[str] = []
    done = 0
    for number, run in enumerate(runs):
        placeholder = f"{token}:{number}"
        pieces += [text[done : run.start], f'{run.indent}- "{placeholder}"']
        weights[placeholder] = run.end - run.start
        done = run.end
    pieces.append(text[done:])
    try:
        data, shared = read_yaml("".join(pieces))
    except yaml.YAMLError:
        return None  # the error as the document itself shows it, from the caller
    if data is None:
        return None
    if shared:
        refuse_alias_bombs(data, len(text), source, weights)
    found = _place_plain_tasks(data, f"{token}:", runs)
    entries = [  # a plain run placed needs none; one that is not is put back as mappings
        run.plain.entries() if run.plain is not None and n not in found else run.items
        for n, run in enumerate(runs)
    ]
    return data if _put_back(data, f"{token}:", entries, found) else None


def _place_plain_tasks(data: Any, prefix: str, runs: list[_Run]) -> set[int]:
    """Put each plain run that is a whole task where the task stands; the numbers placed."""
    tasks = data.get("tasks") if isinstance(data, dict) else None
    placed: set[int] = set()
    if not isinstance(tasks, dict):
        return placed
    for agent, entries in tasks.items():
        if type(entries) is not list or len(entries) != 1 or not isinstance(entries[0], str):
            continue
        number = entries[0].removeprefix(prefix)
        if number == entries[0] or not number.isdigit() or int(number) >= len(runs):
            continue
        plain = runs[int(number)].plain
        if plain is not None and int(number) not in placed:  # an aliased task: put back
            tasks[agent] = plain
            placed.add(int(number))
    return placed


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


def _put_back(data: Any, prefix: str, runs: list[list[dict[str, Any]]], found: set[int]) -> bool:
    """Replace each placeholder item of a list by its run; whether each was found once
    (those in ``found`` were placed before).

    A placeholder anywhere but as a list item (a key, a mapping value) counts as missing.
    """
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
