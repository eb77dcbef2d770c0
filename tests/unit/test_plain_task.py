"""A digested task of plain lines is read from the text of its fields, exactly as YAML reads it.

:func:`~rosmc_server.core.files.document_reading.read_document` with ``plain_tasks`` gives a task
that a document as its writer wrote it holds as one run of skill lines in the plain form as
a :class:`~rosmc_server.core.files.plain_skills.PlainTask` (no mapping per line). Whatever the
lines hold (quotes, escapes, braces, a key more, a parameters text that is not one
mapping), the data it stands for is what YAML reads; a task it cannot take is read as
before, and a wrong entry in one is named as precisely as in an undigested document.
"""

from __future__ import annotations

import json
from dataclasses import replace
from typing import Any

import pytest
import yaml
from hypothesis import given, settings
from hypothesis import strategies as st

from rosmc_server.core import (
    Library,
    MissionContent,
    MissionFileError,
    SkillStatus,
    Transfer,
    parse_mission,
)
from rosmc_server.core.files.document_reading import read_document
from rosmc_server.core.files.mission_reader import mission_from_dict
from rosmc_server.core.files.mission_text import (
    MissionDumper,
    digest_line,
    flow_line,
    skill_to_dict,
)
from rosmc_server.core.files.plain_skills import PlainTask
from rosmc_server.core.model.model import NO_BINDINGS
from tests.unit.random_missions import random_content


def expanded(data: Any) -> Any:
    """``data`` with each plain task as the mappings it stands for."""
    tasks = data.get("tasks") if isinstance(data, dict) else None
    if isinstance(tasks, dict):
        for agent, entries in tasks.items():
            if isinstance(entries, PlainTask):
                tasks[agent] = entries.entries()
    return data


def blueprint(library: Library, skills: int, seed: int) -> MissionContent:
    """Random blueprint skills with their optional fields at the defaults, labels plain,
    each written as one line."""
    content = random_content(library, skills, seed=seed)
    tasks = {
        agent: [
            replace(s, bindings=NO_BINDINGS, timeout=0.0, max_retries=0, label=f"step {i}")
            for i, s in enumerate(task)
            if s.status is SkillStatus.IDLE
            and s.transfer is Transfer.NONE
            and flow_line(skill_to_dict(s)) is not None  # not one in YAML's block style
        ]
        for agent, task in content.tasks.items()
    }
    return MissionContent(content.library, tasks, {}, {})


def digested(lines: list[str]) -> str:
    """A document of one task of ``lines``, ending with its digest."""
    text = "tasks:\n  alpha:\n" + "".join(f"  - {line}\n" for line in lines)
    return text + digest_line(text)


def test_a_digested_blueprint_is_read_from_the_text_of_its_lines(library: Library) -> None:
    content = blueprint(library, 400, seed=5)
    text = MissionDumper().dump(content, 3)
    data = read_document(text, "x", plain_tasks=True)
    assert all(isinstance(data["tasks"][agent], PlainTask) for agent in content.tasks)
    assert [len(data["tasks"][agent]) for agent in content.tasks] == [
        len(task) for task in content.tasks.values()
    ]
    assert expanded(data) == yaml.load(text, Loader=yaml.CSafeLoader)
    assert parse_mission(text, library, "x") == (content, 3)
    # Without the digest, every line is read and checked as before: the same mission.
    undigested = text[: text.rindex("# sha256")]
    assert isinstance(read_document(undigested, "x", plain_tasks=True)["tasks"]["alpha"], list)
    assert parse_mission(undigested, library, "x") == (content, 3)


def test_a_consumed_plain_task_is_emptied(library: Library) -> None:
    content = blueprint(library, 100, seed=2)
    data = read_document(MissionDumper().dump(content, 1), "x", plain_tasks=True)
    tasks = dict(data["tasks"])
    assert mission_from_dict(data, library, "x", consume=True) == (content, 1)
    assert [len(task) for task in tasks.values()] == [0] * len(tasks)


TEXT = st.text(alphabet='ab"\\}{,: é\t\x01/', max_size=8)
VALUE = st.one_of(TEXT, st.integers(-3, 3), st.floats(allow_nan=False), st.booleans())


@st.composite
def entries(draw: st.DrawFn) -> dict[str, Any]:
    """An entry in the plain form or near it: any text in its fields, maybe a key more."""
    entry: dict[str, Any] = {
        "id": draw(st.sampled_from(["a", "b-1"]) | TEXT),
        "skill": draw(st.sampled_from(["move", "wait"]) | TEXT),
        "label": draw(TEXT),
        "params": draw(st.dictionaries(TEXT, VALUE | st.dictionaries(TEXT, VALUE), max_size=3)),
    }
    if draw(st.booleans()):
        entry[draw(TEXT)] = draw(VALUE | st.dictionaries(TEXT, VALUE, max_size=2))
    entry["status"] = draw(st.sampled_from(["IDLE", "SUCCESS"]) | TEXT)
    return entry


@settings(max_examples=300, deadline=None)
@given(st.lists(entries(), min_size=1, max_size=4))
def test_any_digested_lines_read_as_yaml_reads_them(items: list[dict[str, Any]]) -> None:
    lines = [flow_line(item) for item in items]
    if None in lines:  # the writer writes such an entry in YAML's block style
        return
    text = digested([line for line in lines if line is not None])
    assert expanded(read_document(text, "x", plain_tasks=True)) == yaml.load(
        text, Loader=yaml.CSafeLoader
    )


@pytest.mark.parametrize(
    "line",
    [  # plain lines to the pattern; in the first two the parameters text is not one mapping
        '{"id": "a", "skill": "wait", "label": "l", "params": {"x": 1}, "y": {}, "status": "IDLE"}',
        '{"id": "a", "skill": "wait", "label": "l", "params": {}, "n": 1, "p": {}, "status": "X"}',
        '{"id": "a", "skill": "wait", "label": "l", "params": {"q": "}, {"}, "status": "IDLE"}',
    ],
)
def test_lines_whose_parameters_are_not_one_mapping_read_as_yaml_does(line: str) -> None:
    other = '{"id": "b", "skill": "wait", "label": "m", "params": {}, "status": "IDLE"}'
    text = digested([line, other])
    data = read_document(text, "x", plain_tasks=True)
    assert expanded(data) == yaml.load(text, Loader=yaml.CSafeLoader)


def test_an_aliased_plain_task_reads_as_yaml_does() -> None:
    line = '{"id": "a", "skill": "wait", "label": "l", "params": {}, "status": "IDLE"}'
    text = f"tasks:\n  alpha: &t\n  - {line}\n  bravo: *t\n"
    text += digest_line(text)
    data = read_document(text, "x", plain_tasks=True)
    assert expanded(data) == yaml.load(text, Loader=yaml.CSafeLoader)


@pytest.mark.parametrize(
    ("field", "value"),
    [
        ("id", "a b"),
        ("id", "x" * 65),
        ("label", " "),
        ("label", "x" * 121),
        ("skill", "fly"),
        ("status", "idle"),
        ("params", {"seconds": -1}),
        ("params", {"seconds": 1, "extra": 1}),
    ],
)
def test_a_wrong_entry_of_a_digested_task_is_named_as_without_the_digest(
    library: Library, field: str, value: Any
) -> None:
    text = MissionDumper().dump(blueprint(library, 60, seed=4), 1)
    rows = text[: text.rindex("# sha256")].splitlines()
    at = next(i for i, row in enumerate(rows) if '"skill": "wait"' in row and i > 10)
    entry = json.loads(rows[at][4:])
    entry[field] = value
    rows[at] = "  - " + json.dumps(entry, ensure_ascii=False)
    undigested = "\n".join(rows) + "\n"
    with pytest.raises(MissionFileError) as plain:
        parse_mission(undigested, library, "m.yaml")
    with pytest.raises(MissionFileError) as quick:
        parse_mission(undigested + digest_line(undigested), library, "m.yaml")
    assert str(quick.value) == str(plain.value)
    assert "tasks." in str(quick.value)
