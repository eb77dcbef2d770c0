"""A client reading snapshot after snapshot gets what reading each whole gives, reusing the rest.

:class:`~rosmc_server.conversions.task_memory.TaskMemory` lets a client's GetMission answer
take the skills of unchanged records from the last answer. Over a run of random changes
(edits, inserts, deletes, moves, whole new orders, status changes, tasks that appear and
go), each answer must read exactly as a fresh read does, and a skill whose record did not
change must be the very instance read before (that is the saving).
"""

from __future__ import annotations

import random
from dataclasses import replace

import genpy
import pytest

from rosmc_server.conversions.packing import PackedGetMissionResponse, SnapshotPacker, serialized
from rosmc_server.conversions.task_memory import TaskMemory
from rosmc_server.conversions.unpacking import (
    UnpackedGetMissionResponse,
    remembering_get_mission,
)
from rosmc_server.core import Library, MissionContent, SkillInstance, SkillStatus
from rosmc_server.core.skills.library import library_from_dict
from tests.unit.conftest import TEST_LIBRARY
from tests.unit.random_missions import random_content


@pytest.fixture(scope="module")
def library() -> Library:
    return library_from_dict(TEST_LIBRARY)


def answer(content: MissionContent, revision: int) -> bytes:
    return serialized(PackedGetMissionResponse(SnapshotPacker().pack(content, revision, 0.0)))


def changed(
    rng: random.Random, content: MissionContent, spare: list[SkillInstance], changes: int
) -> MissionContent:
    """``content`` after ``changes`` random changes of one kind or another."""
    tasks = {agent: list(task) for agent, task in content.tasks.items()}
    for _ in range(changes):
        agent = rng.choice(sorted(tasks))
        task = tasks[agent]
        kind = rng.choice(["edit", "insert", "delete", "move", "status", "drop"])
        at = rng.randrange(len(task)) if task else 0
        if kind == "edit" and task:
            task[at] = replace(task[at], label=f"edited {rng.random()}")
        elif kind == "insert" and spare:
            task.insert(at, replace(spare.pop(), agent=agent))
        elif kind == "delete" and task:
            del task[at : at + rng.randint(1, 4)]
        elif kind == "move" and task:
            task.insert(rng.randrange(len(task)), task.pop(at))
        elif kind == "status" and task:
            task[at] = replace(task[at], status=SkillStatus.IDLE_SYNCHRONIZED)
        elif kind == "drop" and len(tasks) > 1:
            del tasks[agent]
    return MissionContent(content.library, tasks, {}, content.markers)


def test_every_answer_reads_as_a_fresh_read_and_unchanged_skills_are_reused(
    library: Library,
) -> None:
    rng = random.Random(7)
    content = random_content(library, 600, seed=41)
    content = first = MissionContent(content.library, content.tasks, {}, content.markers)
    spare = [s for task in random_content(library, 200, seed=42).tasks.values() for s in task]
    spare = [replace(s, id=f"spare-{n}") for n, s in enumerate(spare)]
    response = remembering_get_mission(TaskMemory())._response_class
    before: MissionContent | None = None
    local = False  # the last change was one edit, insert, delete or move
    for revision in range(200):
        data = answer(content, revision)
        read = response().deserialize(data)
        fresh = UnpackedGetMissionResponse().deserialize(data)
        assert (read.content, read.revision) == (fresh.content, fresh.revision)
        assert (read.content, read.revision) == (content, revision)
        if before is not None and local:
            last = {s.id: s for task in before.tasks.values() for s in task}
            unchanged = [s for t in read.content.tasks.values() for s in t if last.get(s.id) == s]
            read_again = [s.id for s in unchanged if s is not last[s.id]]
            assert len(read_again) <= 1, (revision, read_again)  # a moved skill is read again
        before = read.content
        kind = rng.choice(["one", "one", "several", "order"])
        local = kind == "one"
        if kind == "order":  # a whole new order of one task
            tasks = dict(content.tasks)
            agent = rng.choice(sorted(tasks))
            tasks[agent] = rng.sample(tasks[agent], len(tasks[agent]))
            content = MissionContent(content.library, tasks, {}, content.markers)
        else:
            content = changed(rng, content, spare, 1 if local else rng.randint(2, 4))
        if revision % 10 == 9:  # tasks that come back after they were dropped
            content = MissionContent(
                content.library, {**first.tasks, **content.tasks}, {}, content.markers
            )
            local = False


def test_a_malformed_answer_after_a_good_one_fails_as_before(library: Library) -> None:
    content = random_content(library, 80, seed=43)
    response = remembering_get_mission(TaskMemory())._response_class
    data = answer(content, 1)
    response().deserialize(data)
    with pytest.raises(genpy.DeserializationError):
        response().deserialize(data[: len(data) // 2])
    assert response().deserialize(data).content == content
