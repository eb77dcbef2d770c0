"""The window's stand-in backend while its ROS node starts: nothing asked meanwhile is lost."""

from __future__ import annotations

from rosmc_rqt_command.core.pending_backend import PendingBackend, follows_replay
from rosmc_rqt_command.core.requests import ask
from tests.unit.test_command_harness import RecordingBackend


def test_requests_and_the_latest_selection_reach_the_bridge_in_order() -> None:
    pending = PendingBackend()
    first = ask(lambda c: c.add_skill, "add wait to alpha", 3)("alpha", "wait")
    second = ask(lambda c: c.delete_skills, "delete", 3)(["alpha-1"])
    pending.request(first)
    pending.publish_selection(["alpha-1"], [])
    pending.request(second)
    pending.publish_selection(["alpha-2"], ["Site"])
    pending.refresh()
    bridge = RecordingBackend()
    pending.hand_over(bridge)
    assert bridge.requests == [first, second]
    assert bridge.selections == [(["alpha-2"], ["Site"])]
    again = RecordingBackend()
    pending.hand_over(again)  # handed over once: a second bridge gets nothing
    assert (again.requests, again.selections) == ([], [])


def test_a_replay_prefix_makes_the_window_read_only() -> None:
    assert not PendingBackend().read_only
    assert not PendingBackend(" / ").read_only
    assert PendingBackend("/replay").read_only
    assert follows_replay("replay") and not follows_replay("")
