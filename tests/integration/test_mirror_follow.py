"""A client's live mission against a real server: MissionFollower and AsyncMissionClient.

The session's real master and a real ``mission_server`` process; this process is the
client node. Changes made through the operator services reach the mirror through the real
``/rosmc/mission_events`` stream; a forged event with a revision gap makes it fetch a
snapshot; a restarted server (a new process whose revisions begin again) is followed; and
calls on the non-blocking client answer by callback, also when the server is gone.
"""

from __future__ import annotations

import threading
from collections.abc import Iterator
from typing import Any

import pytest
import rosmc.msg as wire
import rospy

from rosmc_server import interface
from rosmc_server.core import MarkerType, NotFound, Pose, TaskMarker
from rosmc_server.core.errors import ServerUnavailable
from rosmc_server.core.live.updates import (
    AgentStatusChanged,
    MirrorUpdate,
    MissionReset,
    SkillAdded,
)
from rosmc_server.ros.client import AsyncMissionClient, MissionClient, MissionFollower, Outcome
from tests.conftest import wait_until
from tests.integration.server_fixtures import ServerProcess, StartServer

pytest_plugins = ["tests.integration.server_fixtures"]
pytestmark = pytest.mark.integration


@pytest.fixture
def server(start_server: StartServer) -> ServerProcess:
    return start_server("follow")


@pytest.fixture
def follower(server: ServerProcess) -> Iterator[MissionFollower]:
    follower = MissionFollower(check_period=0.2, retry_period=0.2)
    follower.start()
    yield follower
    follower.close()


def mirrored(follower: MissionFollower, client: MissionClient) -> bool:
    """The mirror is at the server's revision and holds the same mission."""
    state = follower.mirror.state
    if state is None:
        return False
    current = client.fetch_mission()
    return state.revision == current.revision and state.content() == current.content()


def test_the_mirror_follows_changes_made_through_the_services(
    follower: MissionFollower,
) -> None:
    updates: list[MirrorUpdate] = []
    follower.mirror.subscribe(updates.append)
    with MissionClient(timeout=30.0) as client:
        wait_until(lambda: follower.mirror.state is not None, 30.0, "the first snapshot")
        client.add_task_marker(TaskMarker("rss", MarkerType.POSE, Pose(4.0, 2.0)))
        first = client.add_skill("drone", "take_off", {"altitude": 6.0}).skill_id
        second = client.add_skill("drone", "navigate_to", bindings={"target": "rss"}).skill_id
        client.reorder_skills("drone", [second, first])
        client.move_task_marker("rss", Pose(7.0, 1.0))
        client.edit_skill(first, {"altitude": 9.0}, label="higher")
        wait_until(lambda: mirrored(follower, client), 30.0, "the mirror to catch up")
    assert follower.mirror.snapshots_requested == 1
    assert isinstance(updates[0].changes[0], MissionReset)
    added = [c.skill.id for u in updates for c in u.changes if isinstance(c, SkillAdded)]
    assert added == [first, second]
    revisions = [u.revision for u in updates if u.event is not None]
    assert revisions == sorted(revisions) and len(revisions) == len(set(revisions))


def test_a_revision_gap_fetches_one_snapshot(follower: MissionFollower) -> None:
    with MissionClient(timeout=30.0) as client:
        wait_until(lambda: follower.mirror.state is not None, 30.0, "the first snapshot")
        client.add_skill("drone", "land")
        wait_until(lambda: mirrored(follower, client), 30.0, "the mirror to catch up")
        # Another publisher on the events topic: an event three revisions ahead.
        forger = rospy.Publisher(interface.EVENTS_TOPIC, wire.MissionEvent, queue_size=1)
        try:
            wait_until(lambda: forger.get_num_connections() > 0, 30.0, "the follower")
            # An event far ahead: the server never reached it; waiting for it would make
            # the mirror ask for snapshots for ever.
            ahead = client.fetch_mission().revision + 1000
            forger.publish(wire.MissionEvent(revision=ahead, kind=wire.MissionEvent.SKILL_ADDED))
            wait_until(lambda: follower.mirror.ignored_events == 1, 30.0, "the phantom dropped")
            for _ in range(3):
                client.add_skill("drone", "take_off")
            wait_until(lambda: mirrored(follower, client), 30.0, "the mirror to go on")
            assert follower.mirror.snapshots_requested == 2, "one refetch for the gap"
        finally:
            forger.unregister()


def test_an_event_of_another_history_fetches_the_mission(server: ServerProcess) -> None:
    """A server that resumed with lost history names a new epoch in its events: a mirror of
    the old history takes the server's mission whatever its revision."""
    restarts: list[int] = []
    follower = MissionFollower(check_period=0.2, retry_period=0.2, on_restart=restarts.append)
    follower.start()
    forger = rospy.Publisher(interface.EVENTS_TOPIC, wire.MissionEvent, queue_size=1)
    try:
        with MissionClient(timeout=10.0) as client:
            client.add_skill("drone", "land")
            wait_until(lambda: mirrored(follower, client), 10.0, "the mirror to catch up")
            wait_until(lambda: forger.get_num_connections() > 0, 10.0, "the follower")
            revision = client.fetch_mission().revision  # its events named its history
            forger.publish(wire.MissionEvent(revision=revision + 5, kind=0, epoch="another"))
            wait_until(lambda: restarts == [revision], 10.0, "the mission of the new history")
            assert follower.mirror.revision == revision
    finally:
        forger.unregister()
        follower.close()


def test_a_restarted_server_is_followed_from_its_new_mission(
    start_server: StartServer, server: ServerProcess
) -> None:
    connection: list[bool] = []
    follower = MissionFollower(check_period=0.2, retry_period=0.2, on_connection=connection.append)
    follower.start()
    try:
        with MissionClient(timeout=30.0) as client:
            for _ in range(4):
                client.add_skill("drone", "land")
            wait_until(lambda: mirrored(follower, client), 30.0, "the mirror to catch up")
            server.stop()
            wait_until(lambda: connection[-1:] == [False], 30.0, "the server to be missed")
            fresh = start_server("follow-again")  # a new journal: revisions begin again
            assert fresh.alive
            client.close()
            client.get_mission()  # this client's known revision is the old server's
            client.add_skill("science_rover", "explore")
            wait_until(lambda: mirrored(follower, client), 45.0, "the mirror of the new server")
        assert follower.mirror.revision == 2  # the fresh mission's 1, then the one change
        wait_until(lambda: connection == [True, False, True], 10.0, "the new server seen")
    finally:
        follower.close()


def test_async_calls_answer_by_callback_with_one_sentence(server: ServerProcess) -> None:
    outcomes: list[Outcome[Any]] = []
    done = threading.Event()

    def record(outcome: Outcome[Any]) -> None:
        outcomes.append(outcome)
        if len(outcomes) == 2:
            done.set()

    client = AsyncMissionClient(MissionClient(timeout=30.0))
    try:
        added = client.submit(lambda c: c.add_skill("drone", "land"), record)
        client.submit(lambda c: c.edit_skill("no-such-skill", label="x"), record)
        assert done.wait(15.0)
        assert added.result().skill_id.startswith("drone")
        assert outcomes[0].ok and outcomes[0].value == added.result()
        error = outcomes[1].error
        assert isinstance(error, NotFound) and "no-such-skill" in str(error)
        assert "\n" not in str(error) and client.pending == 0
    finally:
        client.close()


def test_async_calls_to_a_missing_server_fail_without_blocking_the_caller(
    server: ServerProcess,
) -> None:
    server.stop()
    outcomes: list[Outcome[Any]] = []
    arrived = threading.Event()
    client = AsyncMissionClient(MissionClient(timeout=0.5))
    try:
        future = client.submit(
            lambda c: c.add_skill("drone", "land"), lambda o: (outcomes.append(o), arrived.set())
        )
        assert not future.done(), "the call waits for the server on the worker, not here"
        assert arrived.wait(10.0)
        assert isinstance(outcomes[0].error, ServerUnavailable)
        assert "mission server is not reachable" in str(outcomes[0].error)
    finally:
        client.close()


def test_a_robot_heard_all_along_is_news_only_when_it_changes(
    server: ServerProcess, follower: MissionFollower, fake_robot: Any
) -> None:
    # The server publishes every robot's status twice a second; a robot heard all along
    # changes only its last_heard there, which is no news for the GUIs.
    wait_until(lambda: follower.mirror.state is not None, 30.0, "the first snapshot")
    robot = fake_robot("drone")
    stop = threading.Event()

    def heartbeat() -> None:
        while not stop.wait(0.2):
            robot.announce()

    beating = threading.Thread(target=heartbeat, daemon=True)
    beating.start()
    published: list[Any] = []
    listener = rospy.Subscriber(
        interface.AGENT_STATES_TOPIC, wire.AgentStates, published.append, queue_size=100
    )
    try:

        def drone_up() -> bool:
            status = follower.mirror.agent_status("drone")
            return status is not None and status.link == "up"

        wait_until(drone_up, 30.0, "the drone's link up")
        updates: list[MirrorUpdate] = []
        follower.mirror.subscribe(lambda update: updates.append(update))
        updates.clear()  # a late listener first gets the whole mission
        published.clear()
        wait_until(lambda: len(published) >= 8, 60.0, "eight agent-state messages")
    finally:
        stop.set()
        beating.join()
        listener.unregister()
    about_drone = [
        change
        for update in updates
        for change in update.changes
        if isinstance(change, AgentStatusChanged) and change.new.agent == "drone"
    ]
    # Before: one per message (8 or more). A busy machine may let last_heard pass a whole
    # second once or twice between two heartbeats.
    assert len(about_drone) <= 2, about_drone
