"""Skill entries checked a column at a time accept and build exactly what entry by entry does.

:func:`~rosmc_server.core.files.plain_skills.read_plain` is a shortcut of the mission reader: for
random tasks of entries in the writer's usual form, some of them wrong in one field (an id,
a label, a skill name, a status, a parameter), it either declines or gives the very skills
the entry-by-entry reader gives, and it takes the usual case: a blueprint written by ROSMC.
A reader told to consume its data (a load's own) empties each task once read, and no other.
"""

from __future__ import annotations

import copy
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
    dump_mission,
    mission_to_dict,
    parse_mission,
)
from rosmc_server.core.documents.documents import DocumentReader
from rosmc_server.core.files.mission_reader import _TaskReader, mission_from_dict
from rosmc_server.core.files.plain_skills import PLAIN_FORM, read_plain
from rosmc_server.core.model.model import NO_BINDINGS
from tests.unit.random_missions import random_content

GOOD = {
    "move": {"target": {"x": 1.0, "y": 2.0}, "speed": 0.5},
    "wait": {"seconds": 3, "verbose": True, "note": "n", "options": {"a": [1]}},
}
# One field of an entry made wrong, or odd but right, in each way the checks look at.
TWISTS: dict[str, list[Any]] = {
    "id": ["", " a", "a b", "a\nb", "x" * 65, "x" * 64, "é", 7, None, "a.b:c-d_e"],
    "skill": ["", " ", "fly", 3, "wait"],
    "label": ["", "  ", " padded ", "tab\t", "x" * 121, " " + "x" * 120, "\xa0nb", "😀", 1.5],
    "status": ["IDLE", "idle", "RUNNING", "", 0, None],
    "params": [
        {},
        {"speed": 0.5},
        {"target": {"x": 1.0}, "speed": 5.0},
        {"target": {"x": 1.0}, "speed": 1},
        {"target": {"q": 1.0}, "speed": 0.5},
        {"target": [1.0], "speed": 0.5},
        {"speed": 0.5, "target": {"x": 1.0}},
        {"target": {"x": 1.0}, "speed": 0.5, "extra": 1},
        [],
    ],
}


def entry(number: int, skill: str = "move") -> dict[str, Any]:
    return {
        "id": f"s-{number}",
        "skill": skill,
        "label": f"step {number}",
        "params": GOOD[skill],
        "status": "IDLE",
    }


def one_by_one(library: Library, entries: list[Any]) -> list[Any]:
    """What the entry-by-entry reader makes of each entry: a skill, or its error."""
    reader = _TaskReader(DocumentReader("x", MissionFileError), library, {})
    made: list[Any] = []
    for i, raw in enumerate(entries):
        skill = reader.quick(raw, "alpha")
        if skill is None:
            try:
                skill = reader.precise(raw, "alpha", f"tasks.alpha[{i}]", set())
            except MissionFileError as error:
                skill = str(error)
        made.append(skill)
    return made


@settings(max_examples=300, deadline=None)
@given(
    st.lists(
        st.tuples(
            st.sampled_from(["move", "wait"]),
            st.one_of(
                st.none(),
                st.sampled_from(sorted(TWISTS)).flatmap(
                    lambda key: st.tuples(st.just(key), st.sampled_from(TWISTS[key]))
                ),
            ),
        ),
        min_size=1,
        max_size=6,
    )
)
def test_a_task_is_declined_or_read_exactly_as_entry_by_entry(
    library: Library, plan: list[tuple[str, tuple[str, Any] | None]]
) -> None:
    entries = []
    for number, (skill, twist) in enumerate(plan):
        raw = entry(number, skill)
        if twist is not None:
            raw[twist[0]] = twist[1]
        entries.append(raw)
    reader = _TaskReader(DocumentReader("x", MissionFileError), library, {})
    batch = read_plain(entries, "alpha", reader.spec, reader.params)
    if batch is not None:
        expected = one_by_one(library, entries)
        assert batch == expected
        assert [type(v) for s in batch for v in s.params.values()] == [
            type(v) for s in expected for v in s.params.values()
        ]


@pytest.mark.parametrize("extra", ["bindings", "attempt", "started", "transfer"])
def test_entries_of_another_form_are_left_to_the_entry_by_entry_reader(
    library: Library, extra: str
) -> None:
    entries = [entry(1), entry(2)]
    entries[1][extra] = 1
    reader = _TaskReader(DocumentReader("x", MissionFileError), library, {})
    assert read_plain(entries, "alpha", reader.spec, reader.params) is None
    keys = dict.fromkeys(reversed(PLAIN_FORM))  # the same keys in another order
    assert read_plain([dict(keys, **entry(3))], "alpha", reader.spec, reader.params) is None


def test_a_blueprint_written_by_rosmc_is_read_a_column_at_a_time(library: Library) -> None:
    content = random_content(library, 400, seed=5)
    blueprint = {  # the random skills with their optional fields at the defaults
        agent: [
            replace(s, bindings=NO_BINDINGS, timeout=0.0, max_retries=0)
            for s in task
            if s.status is SkillStatus.IDLE and s.transfer is Transfer.NONE
        ]
        for agent, task in content.tasks.items()
    }
    text = dump_mission(MissionContent(content.library, blueprint, {}, {}), 3)
    data = yaml.safe_load(text)
    reader = _TaskReader(DocumentReader("x", MissionFileError), library, {})
    read = {
        agent: read_plain(entries, agent, reader.spec, reader.params)
        for agent, entries in data["tasks"].items()
    }
    assert all(len(task) > 10 for task in blueprint.values())
    assert all(task is not None for task in read.values())
    assert parse_mission(text, library, "x")[0].tasks == blueprint


def test_consumed_data_is_emptied_task_by_task_and_other_data_is_left_alone(
    library: Library,
) -> None:
    content = random_content(library, 300, seed=6)
    data = mission_to_dict(content, 1)
    kept = copy.deepcopy(data)
    assert mission_from_dict(data, library, "x") == (content, 1)
    assert data == kept
    assert mission_from_dict(data, library, "x", consume=True) == (content, 1)
    assert [len(entries) for entries in data["tasks"].values()] == [0, 0, 0]
