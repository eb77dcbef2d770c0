"""Several operators at once against one real mission server.

Stale requests are refused with CONFLICT naming the current revision, so no change is
silently lost; under many concurrent writers every accepted change gets its own
revision, revisions are gap-free, and the event stream carries each exactly once.
"""

from __future__ import annotations

import re
import threading
from collections.abc import Callable
from typing import Any

import pytest
import rosmc.msg as wire

pytest.register_assert_rewrite("tests.integration.server_fixtures")

from tests.integration.server_fixtures import (  # noqa: E402
    Client,
    Recorder,
    accepted,
    assert_one_sentence,
    skill_ids,
)

pytest_plugins = ["tests.integration.server_fixtures"]
pytestmark = pytest.mark.integration

E = wire.ErrorCode
PV = wire.ParameterValue
NOW_AT = re.compile(r"now at revision (\d+)\)")


def current_revision_named(error: str) -> int:
    """The current revision a CONFLICT error names."""
    match = NOW_AT.search(error)
    assert match, f"the conflict does not name the current revision: {error!r}"
    return int(match.group(1))


def altitude(value: float) -> list[PV]:
    return [PV(name="altitude", type=PV.FLOAT, float_value=value)]


def find(mission: wire.Mission, skill_id: str) -> wire.Skill:
    return next(s for t in mission.tasks for s in t.skills if s.id == skill_id)


def test_two_operators_with_the_same_revision(fresh: Client) -> None:
    with Client() as other:
        a, b = fresh, other
        rev = a.revision()
        skill = accepted(
            a.call("add_skill", base_revision=rev, agent="drone", skill="take_off", index=-1)
        ).skill_id
        seen = b.revision()  # both operators now look at the same mission
        assert seen == rev + 1
        accepted(a.call("edit_skill", base_revision=seen, skill_id=skill, parameters=altitude(9)))
        late = b.call("edit_skill", base_revision=seen, skill_id=skill, label="from b")
        assert late.error_code == E.CONFLICT
        assert_one_sentence(late.error)
        assert current_revision_named(late.error) == seen + 1 == late.revision
        mission = a.mission()
        assert find(mission, skill).label == "take_off"  # b's change was not applied
        # b fetches, sees a's change and applies its own on top: both survive.
        accepted(b.call("edit_skill", base_revision=late.revision, skill_id=skill, label="b"))
        final = find(b.mission(), skill)
        assert final.label == "b"
        assert final.parameters[0].float_value == 9.0


def _add_until_accepted(client: Client, rev: int, label: str, conflicts: list[str]) -> Any:
    """Add a skill, retrying on CONFLICT with the revision the server names."""
    for _attempt in range(500):
        response = client.call(
            "add_skill",
            base_revision=rev,
            agent="science_rover",
            skill="explore",
            index=-1,
            label=label,
        )
        if response.error_code == E.NONE:
            return response
        assert response.error_code == E.CONFLICT, response.error
        named = current_revision_named(response.error)
        assert rev < named <= response.revision, (rev, response.error, response.revision)
        conflicts.append(response.error)
        rev = response.revision
    raise AssertionError(f"{label} never got through")


def test_racing_operators_lose_no_update(fresh: Client) -> None:
    start = fresh.revision()
    accepted_by: dict[str, list[tuple[str, str, int]]] = {}
    conflicts: list[str] = []
    errors: list[BaseException] = []

    def operator(name: str) -> None:
        try:
            with Client() as client:
                done = accepted_by.setdefault(name, [])
                rev = start
                for number in range(120):
                    label = f"{name}-{number}"
                    response = _add_until_accepted(client, rev, label, conflicts)
                    done.append((response.skill_id, label, response.revision))
                    rev = response.revision
        except BaseException as error:  # reported by the main thread
            errors.append(error)

    threads = [threading.Thread(target=operator, args=(name,)) for name in ("A", "B")]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join(120)
    assert not errors, errors
    assert conflicts, "the operators never raced; the test proves nothing"
    mission = fresh.mission()
    everything = [item for done in accepted_by.values() for item in done]
    assert len(everything) == 240
    assert mission.revision == start + len(everything)
    assert sorted(rev for _, _, rev in everything) == list(range(start + 1, mission.revision + 1))
    labels = {s.id: s.label for s in mission.tasks[1].skills}
    assert labels == {skill_id: label for skill_id, label, _ in everything}


def _hammer(client: Client, name: str, rounds: int, log: list[tuple[int, str]]) -> None:
    """Mixed changes on this thread's own skills and markers, retrying conflicts."""
    rev = client.revision()

    def attempt(operation: str, **fields: Any) -> Any:
        nonlocal rev
        for _ in range(1000):
            response = client.call(operation, base_revision=rev, **fields)
            if response.error_code == E.NONE:
                rev = response.revision
                log.append((response.revision, operation))
                return response
            assert response.error_code == E.CONFLICT, (operation, response.error)
            rev = response.revision
        raise AssertionError(f"{operation} never got through")

    marker = attempt("add_task_marker", marker=wire.TaskMarker(name=f"M-{name}", type=1)).name
    mine: list[str] = []
    agent = ("drone", "science_rover", "manipulator_rover")[int(name[1:]) % 3]
    skill = {"drone": "take_off", "science_rover": "explore", "manipulator_rover": "pick_box"}
    for number in range(rounds):
        step = number % 4
        if step in (0, 1) or not mine:
            mine.append(attempt("add_skill", agent=agent, skill=skill[agent], index=-1).skill_id)
        elif step == 2:
            attempt("edit_skill", skill_id=mine[-1], label=f"{name}-{number}")
        else:
            attempt("move_task_marker", name=marker, pose=wire.Pose6D(x=number))
            attempt("delete_skills", skill_ids=[mine.pop(0)])


def test_many_threads_get_sequential_revisions(
    fresh: Client, events: Callable[[], Recorder]
) -> None:
    recorder = events()
    start = fresh.revision()
    logs: dict[str, list[tuple[int, str]]] = {}
    errors: list[BaseException] = []
    readers_done = threading.Event()
    seen_by_reader: list[int] = []

    def writer(name: str) -> None:
        try:
            with Client() as client:
                _hammer(client, name, 40, logs.setdefault(name, []))
        except BaseException as error:
            errors.append(error)

    def reader() -> None:
        try:
            with Client() as client:
                while not readers_done.is_set():
                    seen_by_reader.append(int(client.mission().revision))
        except BaseException as error:
            errors.append(error)

    writers = [threading.Thread(target=writer, args=(f"w{i}",)) for i in range(8)]
    watcher = threading.Thread(target=reader)
    watcher.start()
    for thread in writers:
        thread.start()
    for thread in writers:
        thread.join(180)
    readers_done.set()
    watcher.join(30)
    assert not errors, errors
    acknowledged = sorted(rev for log in logs.values() for rev, _ in log)
    final = fresh.revision()
    assert acknowledged == list(range(start + 1, final + 1)), "revisions are not one per change"
    got = recorder.wait_for(lambda m: bool(m) and m[-1].revision >= final, timeout=30.0)
    revisions = [e.revision for e in got if e.revision > start]
    assert revisions == list(range(start + 1, final + 1)), "events are not in revision order"
    assert seen_by_reader == sorted(seen_by_reader), "a reader saw the revision go backwards"
    kinds = {
        "add_skill": wire.MissionEvent.SKILL_ADDED,
        "edit_skill": wire.MissionEvent.SKILL_EDITED,
        "delete_skills": wire.MissionEvent.SKILL_DELETED,
        "add_task_marker": wire.MissionEvent.MARKER_ADDED,
        "move_task_marker": wire.MissionEvent.MARKER_MOVED,
    }
    by_revision = {e.revision: e.kind for e in got}
    for log in logs.values():
        for rev, operation in log:
            assert by_revision[rev] == kinds[operation], (rev, operation)
    mission = fresh.mission()
    assert len(mission.markers) == 8
    assert len(skill_ids(mission)) == 8 * 10  # per thread: 20 adds, 10 deletes
