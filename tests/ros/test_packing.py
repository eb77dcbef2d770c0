"""Packed snapshots are byte for byte what genpy writes, and rebuild only what changed.

:mod:`rosmc_server.conversions.packing` writes skills' wire bytes directly and keeps them
between snapshots; a receiver must not be able to tell: every skill of a random 10,000-
skill mission (every status, parameter type and binding, tricky text and numbers) and the
whole snapshot serialize exactly as the genpy messages of ``skill_to_msg`` and
``mission_to_msg`` do, and deserialize to the same message.
"""

from __future__ import annotations

import tracemalloc
from dataclasses import replace
from typing import Any

import pytest
import rosmc.msg as wire
import rosmc.srv as srv

from rosmc_server.conversions import mission_to_msg, packing, skill_to_msg
from rosmc_server.conversions.packing import (
    PACKED_SKILL_MD5,
    PackedGetMissionResponse,
    SnapshotPacker,
    serialized,
    skill_bytes,
)
from rosmc_server.core import Barrier, Library
from rosmc_server.core.skills.library import library_from_dict
from tests.unit.conftest import TEST_LIBRARY
from tests.unit.random_missions import random_content


@pytest.fixture(scope="module")
def library() -> Library:
    return library_from_dict(TEST_LIBRARY)


def test_the_direct_writer_is_in_use() -> None:
    # A changed rosmc/Skill definition falls back to genpy; this test then asks for an update.
    assert wire.Skill._md5sum == PACKED_SKILL_MD5


def test_every_skill_packs_as_genpy_serializes_it(library: Library) -> None:
    content = random_content(library, 10_000, seed=21)
    skills = [skill for task in content.tasks.values() for skill in task]
    assert len(skills) > 9000
    for skill in skills:
        assert skill_bytes(skill) == serialized(skill_to_msg(skill)), skill.id


def test_a_snapshot_packs_as_genpy_serializes_it(library: Library) -> None:
    content = random_content(library, 2000, seed=22)
    assert content.barriers and content.markers
    packed = SnapshotPacker().pack(content, 77, 1732435200.25)
    expected = mission_to_msg(content, 77, 1732435200.25)
    assert serialized(packed) == serialized(expected)
    assert packed.unpacked() == expected
    # The service answer is the snapshot's bytes, as GetMission's genpy answer would be.
    answer = PackedGetMissionResponse(packed)
    assert serialized(answer) == serialized(srv.GetMissionResponse(mission=expected))
    assert "revision 77" in str(packed)


def count_packed(monkeypatch: pytest.MonkeyPatch) -> list[str]:
    """The ids of the skills serialized from now on, in order."""
    packed: list[str] = []
    real = packing.skill_bytes

    def counting(skill: Any, names: Any = None, shared: Any = None) -> bytes:
        packed.append(skill.id)
        return real(skill, names, shared)

    monkeypatch.setattr(packing, "skill_bytes", counting)
    return packed


def test_a_snapshot_after_a_change_serializes_only_the_changed_skills(
    library: Library, monkeypatch: pytest.MonkeyPatch
) -> None:
    content = random_content(library, 3000, seed=23)
    packer = SnapshotPacker()
    packer.pack(content, 1, 0.0)
    packed = count_packed(monkeypatch)
    changed = content.copy()
    old = changed.tasks["charlie"][5]
    changed.tasks["charlie"][5] = replace(old, label="renamed")
    changed.barriers["extra"] = Barrier("extra", (changed.tasks["alpha"][-1].id, old.id))
    snapshot = packer.pack(changed, 2, 5.0)
    assert packed == [old.id]
    assert snapshot.unpacked() == mission_to_msg(changed, 2, 5.0)
    # Skills serialized ahead (a mission about to be loaded) are not serialized again, even
    # after a snapshot of the old mission was built in between.
    fresh = random_content(library, 300, seed=24)
    packer.prepare(fresh)
    packer.pack(changed, 2, 6.0)
    packed.clear()
    assert packer.pack(fresh, 3, 0.0).unpacked() == mission_to_msg(fresh, 3, 0.0)
    assert packed == []


def test_a_task_moved_or_made_of_equal_but_new_skills_packs_afresh(library: Library) -> None:
    content = random_content(library, 600, seed=31)
    packer = SnapshotPacker()
    packer.pack(content, 1, 0.0)
    changed = content.copy()
    task = changed.tasks["alpha"]
    task.insert(0, task.pop())  # every skill of the task moves one place
    assert packer.pack(changed, 2, 0.0).unpacked() == mission_to_msg(changed, 2, 0.0)
    # A skill equal to the one it replaces but not the same (-0.0 == 0.0) has its own
    # bytes: a task is reused whole only while it holds the very same instances.
    zero = replace(task[0], timeout=0.0)
    task[0] = zero
    packer.pack(changed, 3, 0.0)
    task[0] = replace(zero, timeout=-0.0)
    assert task[0] == zero
    snapshot = packer.pack(changed, 4, 0.0)
    assert snapshot.body == SnapshotPacker().body(changed)
    assert snapshot.unpacked() == mission_to_msg(changed, 4, 0.0)


def test_skills_shifted_far_keep_their_bytes(
    library: Library, monkeypatch: pytest.MonkeyPatch
) -> None:
    content = random_content(library, 900, seed=37)
    packer = SnapshotPacker()
    packer.pack(content, 1, 0.0)
    packed = count_packed(monkeypatch)
    changed = content.copy()
    task = changed.tasks["bravo"]
    del task[10:60]  # every later skill moves 50 places
    task[3] = replace(task[3], label="edited")
    first = task.pop(0)
    task.insert(len(task) // 2, first)  # one moved far
    snapshot = packer.pack(changed, 2, 0.0)
    # The edited one (now third, after the move), and the few skills packed afresh before
    # the packer sees that the task changed in more than a few places.
    assert task[2].id in packed
    assert len(packed) <= 1 + packing._FEW_MISSES
    assert snapshot.body == SnapshotPacker().body(changed)


def test_skills_sharing_parameters_pack_as_genpy_serializes_them(library: Library) -> None:
    # A loaded mission's alike parameters are one dict; the bytes written for it serve
    # every skill holding that very dict (and bindings), no other.
    content = random_content(library, 400, seed=25)
    task = content.tasks["alpha"]
    shared = task[0].params
    for index in range(1, len(task), 3):
        task[index] = replace(task[index], params=shared)  # the very dict
    for index in range(2, len(task), 7):
        task[index] = replace(task[index], params=dict(shared))  # equal, another dict
    task[4] = replace(task[4], params=shared, bindings={name: "rock_1" for name in shared})
    packer = SnapshotPacker()
    packer.prepare(content)
    assert serialized(packer.pack(content, 9, 0.0)) == serialized(mission_to_msg(content, 9, 0.0))


def held_while(build: Any) -> tuple[Any, int]:
    """What ``build()`` returns, and the bytes it left allocated (``tracemalloc``)."""
    tracemalloc.start()
    try:
        before = tracemalloc.get_traced_memory()[0]
        result = build()
        return result, tracemalloc.get_traced_memory()[0] - before
    finally:
        tracemalloc.stop()


def test_a_packer_holds_the_skills_bytes_once(library: Library) -> None:
    # The skills' bytes live in the snapshot's body only (no copy per skill beside it), for
    # a loaded mission's first snapshot and for one after a change alike.
    content = random_content(library, 3000, seed=41)
    packer = SnapshotPacker()

    def load() -> bytes:
        packer.prepare(content)
        return bytes(packer.pack(content, 1, 0.0).body)

    body, held = held_while(load)
    assert held < 1.2 * len(body)
    changed = content.copy()
    changed.tasks["alpha"][7] = replace(changed.tasks["alpha"][7], label="renamed")
    body, held = held_while(lambda: packer.pack(changed, 2, 0.0).body)
    assert held < 1.2 * len(body)
    assert body == SnapshotPacker().body(changed)
