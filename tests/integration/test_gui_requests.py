"""One typed request path: every mutating call a GUI makes is made against what it showed.

A real master and ``mission_server``, the command window's real ROS bridge (offscreen Qt)
and the marker node's client worker. Each request is made against the revision the
operator saw; the client fills in the base revision of whatever method it calls (no list
of "mutating" names to forget one in), so a change someone else made first is refused as
a conflict and changes nothing, and a request made against the current revision goes
through.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Iterator
from typing import Any

import pytest

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")

from python_qt_binding.QtWidgets import QApplication

from rosmc_rqt_command.core.requests import Answer, Request, ask
from rosmc_rqt_command.ros_bridge import RosBridge
from rosmc_server.core import MarkerType, Pose, TaskMarker
from rosmc_server.ros.client import AsyncMissionClient, MissionClient, Outcome
from tests import conftest
from tests.integration.server_fixtures import StartServer

pytest_plugins = ["tests.integration.server_fixtures"]

POINT = TaskMarker("", MarkerType.POSITION, Pose(1.0, 2.0))


@pytest.fixture
def bridge(client_node: Any, start_server: StartServer) -> Iterator[RosBridge]:
    """A command window's bridge to a fresh server, following its mission."""
    start_server()
    app = QApplication.instance() or QApplication([])
    made = RosBridge(timeout=5.0)
    made.start()
    yield made
    made.close()
    app.processEvents()


def answer_of(bridge: RosBridge, request: Request) -> Answer:
    """Send ``request`` through the bridge; its answer (on the GUI thread)."""
    answers: list[Answer] = []
    bridge.answered.connect(answers.append)
    try:
        bridge.request(request)
        return conftest.wait_until(
            lambda: answers[0] if answers else None, 30, "the answer", pause=conftest.qt_pause
        )
    finally:
        bridge.answered.disconnect(answers.append)


def mission_now() -> tuple[int, Any]:
    """The server's revision and mission content, read by a separate client."""
    with MissionClient(5.0) as other:
        state = other.get_mission()
        return state.revision, state.content()


def someone_else(change: Callable[[MissionClient], Any]) -> None:
    """Another operator's accepted change."""
    with MissionClient(5.0) as other:
        change(other)


def setup_mission() -> tuple[str, str, str]:
    """Two drone skills and a marker; their ids and the marker's name."""
    with MissionClient(5.0) as other:
        first = other.add_skill("drone", "take_off").skill_id
        second = other.add_skill("drone", "land").skill_id
        marker = other.add_task_marker(POINT).name
    return first, second, marker


CALLS: dict[str, Callable[[str, str, str, int], Request]] = {
    "reorder_skills": lambda a, b, m, seen: ask(lambda c: c.reorder_skills, "move", seen)(
        "drone", moves=[(b, 0)]
    ),
    "add_task_marker": lambda a, b, m, seen: ask(lambda c: c.add_task_marker, "new", seen)(POINT),
    "move_task_marker": lambda a, b, m, seen: ask(lambda c: c.move_task_marker, "move", seen)(
        m, Pose(5.0, 5.0)
    ),
    "delete_task_marker": lambda a, b, m, seen: ask(lambda c: c.delete_task_marker, "del", seen)(m),
    "delete_skills": lambda a, b, m, seen: ask(lambda c: c.delete_skills, "delete", seen)([a]),
}


@pytest.mark.parametrize("operation", sorted(CALLS))
def test_a_request_made_against_an_old_view_is_a_conflict(
    bridge: RosBridge, operation: str
) -> None:
    first, second, marker = setup_mission()
    seen, _ = mission_now()  # what the operator saw when clicking
    someone_else(lambda c: c.add_skill("science_rover", "explore"))
    before = mission_now()

    answer = answer_of(bridge, CALLS[operation](first, second, marker, seen))

    assert answer.request.operation == operation
    assert answer.conflict, answer
    assert "someone else" in answer.error or "revision" in answer.error, answer.error
    assert mission_now() == before  # refused: nothing changed


@pytest.mark.parametrize("operation", sorted(CALLS))
def test_a_request_made_against_the_current_view_goes_through(
    bridge: RosBridge, operation: str
) -> None:
    first, second, marker = setup_mission()
    seen, _ = mission_now()

    answer = answer_of(bridge, CALLS[operation](first, second, marker, seen))

    assert answer.ok, answer
    assert mission_now()[0] == answer.value.revision == seen + 1


def test_a_second_quick_request_is_made_against_the_first_ones_result(
    bridge: RosBridge,
) -> None:
    """Two clicks on one view: the second is not refused because of the first."""
    first, _second, marker = setup_mission()
    seen, _ = mission_now()
    bridge.request(ask(lambda c: c.delete_task_marker, "delete", seen)(marker))
    answer = answer_of(bridge, ask(lambda c: c.delete_skills, "delete", seen)([first]))
    assert answer.ok, answer
    assert mission_now()[0] == seen + 2


def test_the_marker_nodes_worker_fills_the_base_revision_too(
    client_node: Any, start_server: StartServer
) -> None:
    start_server()
    _first, _second, marker = setup_mission()
    seen, _ = mission_now()
    someone_else(lambda c: c.add_skill("science_rover", "explore"))
    worker = AsyncMissionClient(MissionClient(5.0), "test-markers")
    outcomes: list[Outcome[Any]] = []
    try:
        worker.submit(lambda c: c.delete_task_marker(marker), outcomes.append, seen).exception(30)
        worker.submit(lambda c: c.delete_task_marker(marker), outcomes.append, seen + 1).result(30)
    finally:
        worker.close()
    refused, accepted = outcomes
    assert refused.error is not None and "revision" in str(refused.error), refused
    assert accepted.ok, accepted


def test_after_a_fresh_server_requests_are_made_against_its_revisions(
    client_node: Any, start_server: StartServer
) -> None:
    """A new server process with a new mission counts from 1 again: the window's client
    forgets the old server's revisions once the new snapshot arrives."""
    server = start_server()
    app = QApplication.instance() or QApplication([])
    bridge = RosBridge(timeout=5.0)
    bridge.start()
    try:
        for _ in range(3):
            seen = bridge.mirror_revision
            assert answer_of(bridge, ask(lambda c: c.add_task_marker, "new", seen)(POINT)).ok
        server.stop()
        start_server("second")  # an empty mission at revision 1 (0 would mean no check)
        conftest.wait_until(
            lambda: bridge.mirror_revision == 1, 60, "the new mission", pause=conftest.qt_pause
        )
        # Made against what the view shows (1), not the old server's 4: checked, and accepted.
        answer = answer_of(bridge, ask(lambda c: c.add_task_marker, "new", 1)(POINT))
        assert answer.ok, answer
        assert mission_now()[0] == 2
    finally:
        bridge.close()
        app.processEvents()
