"""Blueprint editing: add, edit, delete and reorder skills, and every way they are refused."""

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
    RosmcError,
    RuleViolation,
    SkillStatus,
    TaskMarker,
    Transfer,
)

AREA = TaskMarker("field", MarkerType.AREA, Pose(), (Pose(0, 0), Pose(4, 0), Pose(4, 2)))
SPOT = TaskMarker("spot", MarkerType.POSITION, Pose(3.0, 4.0, 1.0))
GOAL = TaskMarker("goal", MarkerType.POSE, Pose(1.0, 2.0, 0.0, 0.0, 0.0, 1.5))


@pytest.fixture
def markers(mission: Any) -> None:
    for marker in (AREA, SPOT, GOAL):
        mission.add_marker(marker)


# -- add -------------------------------------------------------------------------


def test_add_appends_with_defaults(mission: Any, accepted: Any, drv: Any) -> None:
    event = accepted(mission, EventKind.SKILL_ADDED, mission.add_skill, "alpha", "move")
    skill = event.change.put_skills[0].skill
    assert event.agent == "alpha"
    assert skill.id == "alpha-1" and skill.label == "move"
    assert skill.params == {"target": Pose(0.0, 0.0), "speed": 1.0}
    assert skill.status is SkillStatus.IDLE and skill.transfer is Transfer.NONE
    assert skill.attempt == 1 and skill.bindings == {}
    second = drv.add("alpha", "scan", params={"passes": 3})
    assert drv.ids("alpha") == ["alpha-1", second]
    scan = mission.state.skill(second)
    assert scan.params["passes"] == 3 and scan.params["mode"] == "fast"
    assert scan.params["area"] == [{"x": 0, "y": 0}, {"x": 1, "y": 0}, {"x": 0, "y": 1}]


def test_add_of_skill_without_parameters(mission: Any, drv: Any) -> None:
    skill_id = drv.add("bravo", "noop")
    assert mission.state.skill(skill_id).params == {}


def test_add_normalizes_values(mission: Any, drv: Any) -> None:
    skill_id = drv.add("alpha", "move", params={"speed": 2, "target": {"x": 1, "y": 2}})
    params = mission.state.skill(skill_id).params
    assert params["speed"] == 2.0 and isinstance(params["speed"], float)
    assert params["target"] == Pose(1.0, 2.0)


def test_add_accepts_each_type(mission: Any, drv: Any) -> None:
    skill_id = drv.add(
        "alpha",
        "wait",
        params={"seconds": 5, "verbose": True, "note": "hi", "options": {"a": [1, 2.5, None]}},
    )
    assert mission.state.skill(skill_id).params == {
        "seconds": 5,
        "verbose": True,
        "note": "hi",
        "options": {"a": [1, 2.5, None]},
    }


def test_add_with_label_and_options(mission: Any, drv: Any) -> None:
    skill_id = drv.add("alpha", "move", label="  go north ", timeout=30, max_retries=2)
    skill = mission.state.skill(skill_id)
    assert (skill.label, skill.timeout, skill.max_retries) == ("go north", 30.0, 2)


def test_add_inserts_at_index(mission: Any, accepted: Any, drv: Any) -> None:
    first, second = drv.adds("alpha", 2)
    event = accepted(mission, EventKind.SKILL_ADDED, mission.add_skill, "alpha", "noop", index=1)
    new = event.change.put_skills[0].skill.id
    assert drv.ids("alpha") == [first, new, second]
    assert "position 1" in event.summary
    front = drv.add("alpha", "noop", index=0)
    end = drv.add("alpha", "noop", index=4)
    assert drv.ids("alpha") == [front, first, new, second, end]


def test_add_insert_respects_the_editable_blueprint(mission: Any, drv: Any, rejected: Any) -> None:
    synced = drv.adds("alpha", 2)
    drv.sync("alpha")
    blueprint = drv.add("alpha")
    uploading = drv.add("alpha")
    mission.synchronize("alpha", blueprint)  # blueprint is now being uploaded
    # Synchronized skills occupy 0..1, the upload 2, the editable blueprint starts at 3.
    for index in (0, 1, 2, 5, -1):
        rejected(
            mission,
            InvalidRequest,
            mission.add_skill,
            "alpha",
            "move",
            index=index,
            match="editable blueprint",
        )
    new = drv.add("alpha", "noop", index=3)
    assert drv.ids("alpha") == [*synced, blueprint, new, uploading]


@pytest.mark.parametrize(
    ("agent", "skill", "params", "error", "fragment"),
    [
        ("zulu", "move", {}, NotFound, "no agent 'zulu'"),
        ("base", "move", {}, RuleViolation, "static agent"),
        ("alpha", "fly", {}, NotFound, "no skill 'fly'"),
        ("alpha", "move", {"altitude": 3}, NotFound, "no parameter 'altitude'"),
        ("alpha", "move", {"speed": "fast"}, InvalidRequest, "number"),
        ("alpha", "move", {"speed": True}, InvalidRequest, "number"),
        ("alpha", "move", {"speed": 0.0}, InvalidRequest, "at least 0.1"),
        ("alpha", "move", {"speed": 2.5}, InvalidRequest, "at most 2"),
        ("alpha", "move", {"speed": math.nan}, InvalidRequest, "finite"),
        ("alpha", "move", {"speed": math.inf}, InvalidRequest, "finite"),
        ("alpha", "move", {"speed": -math.inf}, InvalidRequest, "finite"),
        ("alpha", "move", {"target": {"x": math.nan}}, InvalidRequest, "finite"),
        ("alpha", "move", {"target": {"x": math.inf}}, InvalidRequest, "finite"),
        ("alpha", "move", {"target": {"w": 1.0}}, InvalidRequest, "unknown pose fields"),
        ("alpha", "move", {"target": [1, 2]}, InvalidRequest, "pose"),
        ("alpha", "scan", {"passes": 1.0}, InvalidRequest, "whole number"),
        ("alpha", "scan", {"passes": 0}, InvalidRequest, "at least 1"),
        ("alpha", "scan", {"passes": 6}, InvalidRequest, "at most 5"),
        ("alpha", "scan", {"mode": "medium"}, InvalidRequest, "one of"),
        ("alpha", "scan", {"mode": 1}, InvalidRequest, "text"),
        ("alpha", "scan", {"area": "square"}, InvalidRequest, "list"),
        ("alpha", "scan", {"area": [{"x": math.nan}]}, InvalidRequest, "finite"),
        ("alpha", "scan", {"area": [object()]}, InvalidRequest, "not list/dict data"),
        ("alpha", "wait", {"verbose": 1}, InvalidRequest, "true or false"),
        ("alpha", "wait", {"options": [1]}, InvalidRequest, "mapping"),
        ("alpha", "wait", {"options": {1: "a"}}, InvalidRequest, "non-text key"),
    ],
)
def test_add_refuses_bad_requests(
    mission: Any,
    drv: Any,
    rejected: Any,
    agent: str,
    skill: str,
    params: Any,
    error: Any,
    fragment: str,
) -> None:
    drv.add("alpha")  # a non-empty mission, so "unchanged" means something
    rejected(mission, error, mission.add_skill, agent, skill, params, match=fragment)


@pytest.mark.parametrize(
    ("kwargs", "fragment"),
    [
        ({"label": "x" * 121}, "at most 120"),
        ({"label": "two\nlines"}, "one line"),
        ({"label": "\x1b[31mred"}, "printable"),
        ({"label": "zero\u200bwidth"}, "printable"),
        ({"label": 5}, "text"),
        ({"timeout": -1}, "non-negative"),
        ({"timeout": math.nan}, "finite"),
        ({"timeout": math.inf}, "finite"),
        ({"timeout": "10"}, "number"),
        ({"max_retries": -1}, "from 0 to 100"),
        ({"max_retries": 101}, "from 0 to 100"),
        ({"max_retries": 1.0}, "whole number"),
    ],
)
def test_add_refuses_bad_options(mission: Any, rejected: Any, kwargs: Any, fragment: str) -> None:
    rejected(mission, InvalidRequest, mission.add_skill, "alpha", "move", match=fragment, **kwargs)


def test_add_with_bindings_takes_marker_values(mission: Any, drv: Any, markers: None) -> None:
    move = drv.add("alpha", "move", bindings={"target": "goal"})
    scan = drv.add("alpha", "scan", bindings={"area": "field", "point": "spot"})
    move_skill, scan_skill = mission.state.skill(move), mission.state.skill(scan)
    assert move_skill.params["target"] == GOAL.pose
    assert move_skill.bindings == {"target": "goal"}
    assert scan_skill.params["area"] == [{"x": 0, "y": 0}, {"x": 4, "y": 0}, {"x": 4, "y": 2}]
    # A position marker gives its point without orientation.
    assert scan_skill.params["point"] == Pose(3.0, 4.0, 1.0)
    # Position and pose markers are interchangeable.
    drv.add("alpha", "move", bindings={"target": "spot"})
    drv.add("alpha", "scan", bindings={"point": "goal"})
    assert {s.id for s in mission.state.bound_to("goal")} == {move, drv.ids("alpha")[-1]}


@pytest.mark.parametrize(
    ("skill", "bindings", "error", "fragment"),
    [
        ("move", {"target": "nowhere"}, NotFound, "no task marker 'nowhere'"),
        ("move", {"target": "field"}, RuleViolation, "area marker 'field'"),
        ("scan", {"area": "spot"}, RuleViolation, "takes area markers"),
        ("move", {"speed": "spot"}, RuleViolation, "takes no markers"),
        ("move", {"heading": "spot"}, NotFound, "no parameter 'heading'"),
    ],
)
def test_add_refuses_bad_bindings(
    mission: Any,
    rejected: Any,
    markers: None,
    skill: str,
    bindings: Any,
    error: Any,
    fragment: str,
) -> None:
    rejected(mission, error, mission.add_skill, "alpha", skill, bindings=bindings, match=fragment)


def test_add_refuses_a_value_and_a_binding_for_one_parameter(
    mission: Any, rejected: Any, markers: None
) -> None:
    rejected(
        mission,
        InvalidRequest,
        mission.add_skill,
        "alpha",
        "move",
        {"target": {"x": 9.0}},
        bindings={"target": "goal"},
        match="both a value and a marker",
    )


def test_add_on_stale_revision(mission: Any, rejected: Any, drv: Any) -> None:
    drv.add("alpha")
    error = rejected(mission, type(_stale()), mission.add_skill, "alpha", "move", base_revision=0)
    assert (error.base_revision, error.current_revision) == (0, 1)
    assert "revision 0" in str(error) and "revision 1" in str(error)
    drv.mission.add_skill("alpha", "move", base_revision=1)


def _stale() -> Exception:
    from rosmc_server.core import StaleRevision

    return StaleRevision(0, 0)


# -- edit ------------------------------------------------------------------------


def test_edit_values(mission: Any, accepted: Any, drv: Any) -> None:
    skill_id = drv.add("alpha", "scan")
    event = accepted(
        mission, EventKind.SKILL_EDITED, mission.edit_skill, skill_id, {"passes": 4, "mode": "slow"}
    )
    assert event.agent == "alpha" and skill_id in event.summary
    skill = mission.state.skill(skill_id)
    assert skill.params["passes"] == 4 and skill.params["mode"] == "slow"
    assert skill.params["area"] == [{"x": 0, "y": 0}, {"x": 1, "y": 0}, {"x": 0, "y": 1}]


def test_edit_label_and_options(mission: Any, accepted: Any, drv: Any) -> None:
    skill_id = drv.add("alpha")
    accepted(mission, EventKind.SKILL_EDITED, mission.edit_skill, skill_id, label="north")
    accepted(mission, EventKind.SKILL_EDITED, mission.edit_skill, skill_id, timeout=5.5)
    accepted(mission, EventKind.SKILL_EDITED, mission.edit_skill, skill_id, max_retries=3)
    skill = mission.state.skill(skill_id)
    assert (skill.label, skill.timeout, skill.max_retries) == ("north", 5.5, 3)
    assert skill.params == {"target": Pose(), "speed": 1.0}


def test_edit_bind_and_unbind(mission: Any, drv: Any, accepted: Any, markers: None) -> None:
    skill_id = drv.add("alpha", "move")
    accepted(
        mission, EventKind.SKILL_EDITED, mission.edit_skill, skill_id, bindings={"target": "goal"}
    )
    skill = mission.state.skill(skill_id)
    assert skill.bindings == {"target": "goal"} and skill.params["target"] == GOAL.pose
    assert [s.id for s in mission.state.bound_to("goal")] == [skill_id]
    # Rebind to another marker.
    mission.edit_skill(skill_id, bindings={"target": "spot"})
    skill = mission.state.skill(skill_id)
    assert skill.bindings == {"target": "spot"} and skill.params["target"] == Pose(3.0, 4.0, 1.0)
    assert mission.state.bound_to("goal") == []
    # Unbinding keeps the value.
    mission.edit_skill(skill_id, bindings={"target": None})
    skill = mission.state.skill(skill_id)
    assert skill.bindings == {} and skill.params["target"] == Pose(3.0, 4.0, 1.0)
    assert mission.state.bound_to("spot") == []
    # A value replaces the binding.
    mission.edit_skill(skill_id, bindings={"target": "goal"})
    mission.edit_skill(skill_id, {"target": {"x": 7.0}})
    skill = mission.state.skill(skill_id)
    assert skill.bindings == {} and skill.params["target"] == Pose(7.0)
    assert mission.state.bound_to("goal") == []
    # "" unbinds too.
    mission.edit_skill(skill_id, bindings={"target": "goal"})
    mission.edit_skill(skill_id, bindings={"target": ""})
    assert mission.state.skill(skill_id).bindings == {}


@pytest.mark.parametrize(
    ("params", "kwargs", "error", "fragment"),
    [
        ({}, {}, InvalidRequest, "changes nothing"),
        ({"speed": 3.0}, {}, InvalidRequest, "at most 2"),
        ({"speed": math.nan}, {}, InvalidRequest, "finite"),
        ({"speed": None}, {}, InvalidRequest, "number"),
        ({"heading": 1}, {}, NotFound, "no parameter 'heading'"),
        ({}, {"label": "   "}, InvalidRequest, "must not be empty"),
        ({}, {"label": "a\tb"}, InvalidRequest, "one line"),
        ({}, {"timeout": -0.5}, InvalidRequest, "non-negative"),
        ({}, {"max_retries": 1000}, InvalidRequest, "from 0 to 100"),
        ({}, {"bindings": {"target": "nowhere"}}, NotFound, "no task marker"),
        ({}, {"bindings": {"target": "field"}}, RuleViolation, "area marker"),
        ({}, {"bindings": {"speed": "spot"}}, RuleViolation, "takes no markers"),
        ({}, {"bindings": {"heading": None}}, NotFound, "no parameter 'heading'"),
        ({"target": {"x": 1.0}}, {"bindings": {"target": "goal"}}, InvalidRequest, "both"),
    ],
)
def test_edit_refuses_bad_requests(
    mission: Any,
    drv: Any,
    rejected: Any,
    markers: None,
    params: Any,
    kwargs: Any,
    error: Any,
    fragment: str,
) -> None:
    skill_id = drv.add("alpha", "move", bindings={"target": "spot"})
    rejected(mission, error, mission.edit_skill, skill_id, params, match=fragment, **kwargs)


def test_edit_refuses_unknown_skill(mission: Any, rejected: Any) -> None:
    rejected(mission, NotFound, mission.edit_skill, "ghost", {"speed": 1.0}, match="'ghost'")


def test_edit_refused_outside_the_editable_blueprint(mission: Any, drv: Any, rejected: Any) -> None:
    synced, running, uploading = drv.adds("alpha", 3)
    drv.sync("alpha", running)
    drv.run(synced)
    mission.synchronize("alpha", uploading)
    for skill_id, state in (
        (synced, "RUNNING"),
        (running, "IDLE_SYNCHRONIZED"),
        (uploading, "being uploaded"),
    ):
        rejected(mission, RuleViolation, mission.edit_skill, skill_id, {"speed": 1.5}, match=state)
        rejected(mission, RuleViolation, mission.edit_skill, skill_id, label="x", match=state)
        rejected(mission, RuleViolation, mission.delete_skills, [skill_id], match=state)


def test_edit_refused_for_finished_skills(mission: Any, drv: Any, rejected: Any) -> None:
    done, failed = drv.adds("alpha", 2)
    drv.sync("alpha")
    drv.finish(done)
    drv.finish(failed, SkillStatus.FAILURE)
    for skill_id in (done, failed):
        rejected(mission, RuleViolation, mission.edit_skill, skill_id, {"speed": 1.5})
        rejected(mission, RuleViolation, mission.delete_skills, [skill_id])


def test_edit_refused_while_unsync_pending(mission: Any, drv: Any, rejected: Any) -> None:
    skill_id = drv.add("alpha")
    drv.sync("alpha")
    mission.unsynchronize("alpha")
    rejected(mission, RuleViolation, mission.edit_skill, skill_id, {"speed": 1.5})
    rejected(mission, RuleViolation, mission.delete_skills, [skill_id])


# -- delete ----------------------------------------------------------------------


def test_delete(mission: Any, drv: Any, accepted: Any) -> None:
    a1, a2, a3 = drv.adds("alpha", 3)
    b1 = drv.add("bravo")
    event = accepted(mission, EventKind.SKILL_DELETED, mission.delete_skills, [a2])
    assert event.agent == "alpha" and a2 in event.summary
    assert drv.ids("alpha") == [a1, a3]
    event = accepted(mission, EventKind.SKILL_DELETED, mission.delete_skills, [a3, b1])
    assert event.agent == ""
    assert drv.ids("alpha") == [a1] and drv.ids("bravo") == []
    assert not mission.state.has_skill(b1)


def test_delete_unbinds_markers(mission: Any, drv: Any, markers: None) -> None:
    skill_id = drv.add("alpha", "move", bindings={"target": "goal"})
    mission.delete_skills([skill_id])
    assert mission.state.bound_to("goal") == []
    mission.delete_marker("goal")


@pytest.mark.parametrize(
    ("ids", "error", "fragment"),
    [
        ([], InvalidRequest, "no skills"),
        (["ghost"], NotFound, "'ghost'"),
        (["A", "ghost"], NotFound, "'ghost'"),
        (["A", "A"], InvalidRequest, "twice"),
    ],
)
def test_delete_refuses(
    mission: Any, drv: Any, rejected: Any, ids: list[str], error: Any, fragment: str
) -> None:
    real = drv.add("alpha")
    ids = [real if i == "A" else i for i in ids]
    rejected(mission, error, mission.delete_skills, ids, match=fragment)


def test_delete_shrinks_and_dissolves_barriers(mission: Any, drv: Any) -> None:
    a, b, c = drv.add("alpha"), drv.add("bravo"), drv.add("charlie")
    barrier = mission.add_barrier([a, b, c]).change.put_barriers[0].id
    event = mission.delete_skills([c])
    assert mission.state.barrier(barrier).skill_ids == (a, b)
    assert event.change.put_barriers[0].skill_ids == (a, b)
    mission.delete_skills([a])
    assert mission.state.barriers == ()
    assert mission.state.barrier_of(b) is None


def test_delete_of_two_members_dissolves_the_barrier(mission: Any, drv: Any) -> None:
    a, b = drv.add("alpha"), drv.add("bravo")
    mission.add_barrier([a, b])
    mission.delete_skills([a, b])
    assert mission.state.barriers == ()


def test_delete_refused_when_barrier_partner_has_started(
    mission: Any, drv: Any, rejected: Any
) -> None:
    a, b = drv.add("alpha"), drv.add("bravo")
    mission.add_barrier([a, b])
    drv.sync("bravo")
    mission.report_status(b, SkillStatus.SYNCWAITING)
    # b waits on its robot for a; deleting a would change a barrier that has started.
    rejected(mission, RuleViolation, mission.delete_skills, [a], match="SYNCWAITING")


# -- reorder ---------------------------------------------------------------------


def test_reorder(mission: Any, drv: Any, accepted: Any) -> None:
    a1, a2, a3 = drv.adds("alpha", 3)
    event = accepted(mission, EventKind.SKILLS_REORDERED, mission.reorder, "alpha", [a3, a1, a2])
    assert event.agent == "alpha"
    assert drv.ids("alpha") == [a3, a1, a2]


def test_reorder_only_touches_the_editable_blueprint(mission: Any, drv: Any) -> None:
    s1, s2, up, b1, b2 = drv.adds("alpha", 5)
    drv.sync("alpha", s2)
    mission.synchronize("alpha", up)
    mission.reorder("alpha", [b2, b1])
    assert drv.ids("alpha") == [s1, s2, up, b2, b1]


@pytest.mark.parametrize(
    ("order", "fragment"),
    [
        (["b2"], "got 1 ids"),
        (["b1", "b2", "b3"], "got 3 ids"),
        (["b1", "b1"], "exactly once"),
        (["b1", "ghost"], "exactly once"),
        (["b1", "s1"], "exactly once"),
        (["b1", "other"], "exactly once"),
        (["b1", "b2", "s1"], "got 3 ids"),
        ([], "got 0 ids"),
    ],
)
def test_reorder_refuses(
    mission: Any, drv: Any, rejected: Any, order: list[str], fragment: str
) -> None:
    s1, b1, b2 = drv.adds("alpha", 3)
    other = drv.add("bravo")
    drv.sync("alpha", s1)
    names = {"s1": s1, "b1": b1, "b2": b2, "other": other}
    order = [names.get(name, name) for name in order]
    rejected(mission, InvalidRequest, mission.reorder, "alpha", order, match=fragment)


def test_reorder_refuses_unknown_agent(mission: Any, rejected: Any) -> None:
    rejected(mission, NotFound, mission.reorder, "zulu", [], match="zulu")
    rejected(mission, NotFound, mission.reorder, "base", [], match="base")


def test_reorder_that_would_deadlock_is_refused(mission: Any, drv: Any, rejected: Any) -> None:
    x1, y1 = drv.adds("alpha", 2)
    x2, y2 = drv.adds("bravo", 2)
    mission.add_barrier([x1, x2])
    mission.add_barrier([y1, y2])
    error = rejected(mission, RuleViolation, mission.reorder, "bravo", [y2, x2], match="deadlock")
    assert f"runs '{y2}' before '{x2}'" in str(error)
    assert f"runs '{x1}' before '{y1}'" in str(error)
    z2 = drv.add("bravo")
    mission.reorder("bravo", [x2, z2, y2])  # keeps x before y: no cycle
    assert drv.ids("bravo") == [x2, z2, y2]


def test_errors_quote_a_short_escaped_excerpt_of_huge_input(mission: Any) -> None:
    with pytest.raises(RosmcError) as caught:
        mission.add_skill("\x1b[2J" + "a" * 2**20, "noop")
    message = str(caught.value)
    assert len(message) < 300 and "\x1b" not in message, message[:300]
    assert "(1048580 characters)" in message
