"""Task markers: add, move, rename, delete, and the locks that bound skills impose."""

from __future__ import annotations

import math
from typing import Any

import pytest

from rosmc_server.core import (
    EventKind,
    InvalidRequest,
    MarkerType,
    NotFound,
    Pose,
    RuleViolation,
    SkillStatus,
    StaleRevision,
    TaskMarker,
)
from rosmc_server.core.rules.edit_rules import MarkerAction, legal_marker_actions

TRIANGLE = (Pose(0.0, 0.0), Pose(3.0, 0.0), Pose(0.0, 3.0, 3.0))


def marker(name: str = "", kind: MarkerType = MarkerType.POSE, **kwargs: Any) -> TaskMarker:
    return TaskMarker(name, kind, kwargs.pop("pose", Pose(1.0, 2.0)), **kwargs)


# -- add -------------------------------------------------------------------------


def test_add_named_marker(mission: Any, accepted: Any) -> None:
    event = accepted(mission, EventKind.MARKER_ADDED, mission.add_marker, marker("  rock  "))
    assert event.change.put_markers[0].name == "rock"
    assert mission.state.marker("rock").pose == Pose(1.0, 2.0)
    assert "rock" in event.summary


def test_add_generates_names(mission: Any) -> None:
    names = [
        mission.add_marker(marker("", kind)).change.put_markers[0].name
        for kind in (MarkerType.POSE, MarkerType.POSE, MarkerType.POSITION)
    ]
    assert names == ["Pose 1", "Pose 2", "Position 1"]
    area = mission.add_marker(marker(" ", MarkerType.AREA, vertices=TRIANGLE))
    assert area.change.put_markers[0].name == "Area 1"
    mission.delete_marker("Pose 1")
    assert mission.add_marker(marker()).change.put_markers[0].name == "Pose 1"
    mission.add_marker(marker("Pose 7"))
    assert mission.add_marker(marker()).change.put_markers[0].name == "Pose 3"


def test_area_gets_its_centroid(mission: Any) -> None:
    mission.add_marker(marker("field", MarkerType.AREA, pose=Pose(50.0, 50.0), vertices=TRIANGLE))
    area = mission.state.marker("field")
    assert area.pose == Pose(1.0, 1.0, 1.0)
    assert area.vertices == TRIANGLE


@pytest.mark.parametrize(
    ("new", "error", "fragment"),
    [
        (marker("rock"), RuleViolation, "already exists"),
        (marker(" rock "), RuleViolation, "already exists"),
        (marker("field", MarkerType.AREA), InvalidRequest, "at least 3 vertices"),
        (marker("f", MarkerType.AREA, vertices=TRIANGLE[:2]), InvalidRequest, "at least 3"),
        (marker("p", MarkerType.POSE, vertices=TRIANGLE), InvalidRequest, "takes no vertices"),
        (marker("p", MarkerType.POSITION, vertices=TRIANGLE), InvalidRequest, "no vertices"),
        (marker("x" * 81), InvalidRequest, "at most 80"),
        (marker("two\nlines"), InvalidRequest, "one line"),
        (marker("nan", pose=Pose(math.nan)), InvalidRequest, "finite"),
        (marker("inf", pose=Pose(0.0, math.inf)), InvalidRequest, "finite"),
        (
            marker("v", MarkerType.AREA, vertices=(*TRIANGLE, Pose(math.nan))),
            InvalidRequest,
            "finite",
        ),
    ],
)
def test_add_refusals(mission: Any, rejected: Any, new: Any, error: Any, fragment: str) -> None:
    mission.add_marker(marker("rock"))
    rejected(mission, error, mission.add_marker, new, match=fragment)


def test_add_on_stale_revision(mission: Any, rejected: Any) -> None:
    mission.add_marker(marker("rock"))
    rejected(mission, StaleRevision, mission.add_marker, marker("b"), base_revision=0)


# -- move ------------------------------------------------------------------------


@pytest.fixture
def bound(mission: Any, drv: Any) -> dict[str, str]:
    """Markers 'goal' (pose), 'spot' (position), 'field' (area), each bound to a blueprint skill."""
    mission.add_marker(marker("goal", MarkerType.POSE, pose=Pose(1.0, 1.0, 0.0, 0.0, 0.0, 0.5)))
    mission.add_marker(marker("spot", MarkerType.POSITION, pose=Pose(2.0, 2.0)))
    mission.add_marker(marker("field", MarkerType.AREA, vertices=TRIANGLE))
    return {
        "move": drv.add("alpha", "move", bindings={"target": "goal"}),
        "scan": drv.add("bravo", "scan", bindings={"area": "field", "point": "spot"}),
        "move2": drv.add("bravo", "move", bindings={"target": "goal"}),
    }


def test_move_updates_bound_parameters(mission: Any, accepted: Any, bound: Any) -> None:
    new_pose = Pose(5.0, 6.0, 0.0, 0.0, 0.0, 1.0)
    event = accepted(mission, EventKind.MARKER_MOVED, mission.move_marker, "goal", new_pose)
    assert "2 bound skills" in event.summary
    assert mission.state.marker("goal").pose == new_pose
    for skill_id in (bound["move"], bound["move2"]):
        assert mission.state.skill(skill_id).params["target"] == new_pose
    # A position marker gives its point; its heading is not taken over.
    mission.move_marker("spot", Pose(7.0, 8.0, 0.0, 0.0, 0.0, 2.0))
    assert mission.state.skill(bound["scan"]).params["point"] == Pose(7.0, 8.0)
    # Unbound parameters stay as they were.
    assert mission.state.skill(bound["scan"]).params["mode"] == "fast"


def test_move_area_updates_vertices_and_centroid(mission: Any, bound: Any) -> None:
    square = (Pose(0.0, 0.0), Pose(2.0, 0.0), Pose(2.0, 2.0), Pose(0.0, 2.0))
    mission.move_marker("field", Pose(), square)
    area = mission.state.marker("field")
    assert area.vertices == square and area.pose == Pose(1.0, 1.0)
    assert mission.state.skill(bound["scan"]).params["area"] == [
        {"x": 0.0, "y": 0.0},
        {"x": 2.0, "y": 0.0},
        {"x": 2.0, "y": 2.0},
        {"x": 0.0, "y": 2.0},
    ]


def test_move_unbound_marker(mission: Any, accepted: Any) -> None:
    mission.add_marker(marker("rock"))
    event = accepted(mission, EventKind.MARKER_MOVED, mission.move_marker, "rock", Pose(9.0))
    assert event.change.put_skills == ()


@pytest.mark.parametrize(
    ("name", "pose", "vertices", "error", "fragment"),
    [
        ("ghost", Pose(), (), NotFound, "'ghost'"),
        ("goal", Pose(math.nan), (), InvalidRequest, "finite"),
        ("goal", Pose(), TRIANGLE, InvalidRequest, "no vertices"),
        ("field", Pose(), TRIANGLE[:2], InvalidRequest, "at least 3"),
        ("field", Pose(), (), InvalidRequest, "at least 3"),
    ],
)
def test_move_refusals(
    mission: Any, rejected: Any, bound: Any, name: str, pose: Any, vertices: Any, error: Any,
    fragment: str,
) -> None:  # fmt: skip
    rejected(mission, error, mission.move_marker, name, pose, vertices, match=fragment)


def test_move_refused_when_bound_to_a_synchronized_skill(
    mission: Any, drv: Any, rejected: Any, bound: Any
) -> None:
    mission.synchronize("alpha")
    rejected(mission, RuleViolation, mission.move_marker, "goal", Pose(3.0), match=bound["move"])
    mission.confirm_synchronized("alpha", [bound["move"]])
    rejected(mission, RuleViolation, mission.move_marker, "goal", Pose(3.0), match="synchronized")
    drv.finish(bound["move"])
    # Finished, the skill no longer locks the marker (issue 9); it keeps what it ran with.
    ran_with = mission.state.skill(bound["move"]).params["target"]
    mission.move_marker("goal", Pose(3.0))
    assert mission.state.skill(bound["move"]).params["target"] == ran_with
    assert mission.state.skill(bound["move2"]).params["target"] == Pose(3.0)
    # The other markers are only bound to blueprint skills and still move.
    mission.move_marker("spot", Pose(3.0))


# -- rename ----------------------------------------------------------------------


def test_rename_propagates_to_bindings(mission: Any, accepted: Any, bound: Any) -> None:
    event = accepted(mission, EventKind.MARKER_RENAMED, mission.rename_marker, "goal", " target ")
    assert "'goal' renamed to 'target'" in event.summary
    assert not mission.state.has_marker("goal")
    assert mission.state.marker("target").pose == Pose(1.0, 1.0, 0.0, 0.0, 0.0, 0.5)
    for skill_id in (bound["move"], bound["move2"]):
        assert mission.state.skill(skill_id).bindings == {"target": "target"}
    assert [s.id for s in mission.state.bound_to("target")] == [bound["move"], bound["move2"]]
    assert mission.state.bound_to("goal") == []
    # The other binding of scan is untouched.
    mission.rename_marker("spot", "point")
    assert mission.state.skill(bound["scan"]).bindings == {"area": "field", "point": "point"}
    # Moving the renamed marker still reaches the skills.
    mission.move_marker("target", Pose(4.0))
    assert mission.state.skill(bound["move"]).params["target"] == Pose(4.0)


@pytest.mark.parametrize(
    ("name", "new_name", "error", "fragment"),
    [
        ("ghost", "x", NotFound, "'ghost'"),
        ("goal", "goal", InvalidRequest, "already has that name"),
        ("goal", " goal ", InvalidRequest, "already has that name"),
        ("goal", "spot", RuleViolation, "already exists"),
        ("goal", "", InvalidRequest, "must not be empty"),
        ("goal", "a\tb", InvalidRequest, "one line"),
    ],
)
def test_rename_refusals(
    mission: Any, rejected: Any, bound: Any, name: str, new_name: str, error: Any, fragment: str
) -> None:
    rejected(mission, error, mission.rename_marker, name, new_name, match=fragment)


def test_rename_refused_when_locked(mission: Any, drv: Any, rejected: Any, bound: Any) -> None:
    drv.sync("bravo", bound["scan"])
    rejected(mission, RuleViolation, mission.rename_marker, "field", "zone", match="synchronized")
    rejected(mission, RuleViolation, mission.rename_marker, "spot", "dot", match=bound["scan"])
    mission.rename_marker("goal", "target")


# -- delete ----------------------------------------------------------------------


def test_delete_marker(mission: Any, accepted: Any) -> None:
    mission.add_marker(marker("rock"))
    accepted(mission, EventKind.MARKER_DELETED, mission.delete_marker, "rock")
    assert not mission.state.has_marker("rock")


def test_delete_refused_when_in_use(mission: Any, drv: Any, rejected: Any, bound: Any) -> None:
    error = rejected(mission, RuleViolation, mission.delete_marker, "goal", match="in use")
    assert bound["move"] in str(error) and bound["move2"] in str(error)
    rejected(mission, NotFound, mission.delete_marker, "ghost")
    rejected(mission, StaleRevision, mission.delete_marker, "goal", base_revision=0)
    # Once nothing is bound it can go.
    mission.edit_skill(bound["move"], bindings={"target": None})
    mission.delete_skills([bound["move2"]])
    mission.delete_marker("goal")
    # A finished skill keeps its marker in use for good.
    drv.sync("bravo")
    drv.finish(bound["scan"])
    rejected(mission, RuleViolation, mission.delete_marker, "spot", match="in use")
    assert mission.state.skill(bound["scan"]).status is SkillStatus.SUCCESS


# -- what a GUI offers -------------------------------------------------------------
MARKERS = ("goal", "spot", "field", "rock")


def attempt(mission: Any, name: str, action: MarkerAction) -> None:
    """The operation a GUI sends for ``action`` on marker ``name`` (moved where it is)."""
    if action is MarkerAction.MOVE:
        where = mission.state.marker(name)
        mission.move_marker(name, where.pose, where.vertices)
    elif action is MarkerAction.RENAME:
        mission.rename_marker(name, f"{name} 2")
    else:
        mission.delete_marker(name)


def test_the_offered_marker_actions_are_the_ones_accepted(
    mission: Any, drv: Any, bound: Any
) -> None:
    """legal_marker_actions says of each marker what the operations then accept."""
    mission.add_marker(marker("rock"))
    drv.sync("bravo", bound["scan"])  # 'field' and 'spot' locked; 'goal' and 'rock' not
    offered = {name: legal_marker_actions(mission.state, name) for name in MARKERS}
    assert offered == {
        "goal": {MarkerAction.MOVE, MarkerAction.RENAME},
        "spot": set(),
        "field": set(),
        "rock": set(MarkerAction),
    }
    for name in MARKERS:
        for action in MarkerAction:
            try:
                attempt(mission, name, action)
            except RuleViolation:
                assert action not in offered[name], (name, action)
            else:
                assert action in offered[name], (name, action)
                mission.undo(mission.revision)  # back to the marker as it was
            assert mission.state.has_marker(name), (name, action)
