"""Skills and poses assembled without their constructors are the ones the constructors build.

Readers of thousands of skills (mission files, snapshots from the wire) build them with
``SkillInstance.assemble`` and ``Pose.assemble``, which fill the instance's fields directly.
They must give the very objects the constructors give: every field, in field order (so
that the instance dict stays compact), equal and hashing alike.
"""

from __future__ import annotations

import dataclasses
from typing import Any

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from rosmc_server.core import Library, Pose, SkillInstance
from rosmc_server.core.model.model import NO_BINDINGS, skill_with
from tests.unit.random_missions import random_content


def fields_of(made: Any) -> dict[str, Any]:
    return {f.name: getattr(made, f.name) for f in dataclasses.fields(made)}


def same_object(assembled: Any, made: Any) -> None:
    assert type(assembled) is type(made)
    if hasattr(made, "__dict__"):  # the instance dict is compact: fields in field order
        assert list(vars(assembled)) == [f.name for f in dataclasses.fields(made)]
    assert fields_of(assembled) == fields_of(made)
    assert assembled == made


@given(st.tuples(*[st.floats(allow_nan=False)] * 6))
def test_an_assembled_pose_is_the_pose_the_constructor_builds(fields: tuple[float, ...]) -> None:
    made, assembled = Pose(*fields), Pose.assemble(*fields)
    same_object(assembled, made)
    assert hash(assembled) == hash(made)


@settings(max_examples=20, deadline=None)
@given(st.integers(0, 2**32 - 1))
def test_an_assembled_skill_is_the_skill_the_constructor_builds(
    library: Library, seed: int
) -> None:
    content = random_content(library, 40, seed=seed)
    for task in content.tasks.values():
        for made in task:
            fields = [getattr(made, f.name) for f in dataclasses.fields(made)]
            same_object(SkillInstance.assemble(*fields), SkillInstance(*fields))


@settings(max_examples=20, deadline=None)
@given(st.integers(0, 2**32 - 1))
def test_skills_assembled_a_column_at_a_time_are_the_skills_the_constructor_builds(
    library: Library, seed: int
) -> None:
    content = random_content(library, 40, seed=seed)
    made = [skill for task in content.tasks.values() for skill in task]
    rows = [[getattr(skill, f.name) for f in dataclasses.fields(skill)] for skill in made]
    for row in rows:
        row[5] = row[5] or NO_BINDINGS  # as assemble_columns takes bindings
    columns = [list(column) for column in zip(*rows, strict=True)]
    assembled = SkillInstance.assemble_columns(len(made), columns)
    assert len(assembled) == len(made)
    for one, other in zip(assembled, made, strict=True):
        same_object(one, other)
    assert SkillInstance.assemble_columns(0, [[]] * len(columns)) == []


@settings(max_examples=20, deadline=None)
@given(
    st.integers(0, 2**32 - 1), st.sampled_from([f.name for f in dataclasses.fields(SkillInstance)])
)
def test_a_skill_with_a_change_is_the_skill_replace_gives(
    library: Library, seed: int, name: str
) -> None:
    content = random_content(library, 20, seed=seed)
    other = random_content(library, 20, seed=seed + 1)
    donors = [skill for task in other.tasks.values() for skill in task]
    for task in content.tasks.values():
        for number, made in enumerate(task):
            value = getattr(donors[number % len(donors)], name)
            changed = skill_with(made, **{name: value})
            same_object(changed, dataclasses.replace(made, **{name: value}))
            assert getattr(changed, name) is value  # as given, not a copy or a stand-in
            assert fields_of(made) == fields_of(dataclasses.replace(made))  # untouched


def test_a_skill_with_an_unknown_field_is_refused() -> None:
    skill = SkillInstance("s1", "robot", "wait", "wait", {})
    with pytest.raises(TypeError, match="no field 'colour'"):
        skill_with(skill, colour="red")
    assert skill_with(skill, bindings={}).bindings == {}
