"""rviz_station's remappings: rviz on the live topics, or on a replay's behind its prefix."""

from __future__ import annotations

from rosmc_rviz_markers.ros.rviz_window import FOLLOWED, remaps


def test_the_live_mission_needs_no_remapping() -> None:
    assert remaps("") == []


def test_a_replay_moves_every_followed_topic_behind_its_prefix() -> None:
    moved = dict(arg.split(":=") for arg in remaps("/replay"))
    assert set(moved) == set(FOLLOWED)
    assert all(to == f"/replay{name}" for name, to in moved.items())
    for name in ("/rosmc/markers/update", "/rosmc/markers/clock", "/tf", "/rosmc/sim/world"):
        assert name in moved, name
