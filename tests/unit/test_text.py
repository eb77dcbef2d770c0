"""Text and JSON views of missions, libraries and events (rosmc_server.text)."""

from __future__ import annotations

import json
from typing import Any

import pytest

from rosmc_server.core import (
    AgentStatus,
    Library,
    MarkerType,
    Mission,
    ParamType,
    Pose,
    SkillStatus,
    TaskMarker,
)
from rosmc_server.core.skills.params import parse_text
from rosmc_server.text import (
    event_to_json,
    format_agent_status,
    format_event,
    format_library,
    format_markers,
    format_tasks,
    format_value,
    library_to_json,
    mission_to_json,
)


@pytest.fixture
def planned(mission: Mission, drv: Any) -> Mission:
    """alpha: one synced running skill + a blueprint; bravo: a barrier partner; a marker."""
    mission.add_marker(TaskMarker("Spot", MarkerType.POSE, Pose(3.0, 4.0, 0.0, 0.0, 0.0, 1.5)))
    first = drv.add("alpha", "move", params={"speed": 1.5}, label="go")
    drv.sync("alpha")
    drv.run(first)
    scan = drv.add("alpha", "scan", bindings={"point": "Spot"})
    drv.add("alpha", "wait", params={"seconds": 3})
    partner = drv.add("bravo", "scan")
    mission.add_barrier([scan, partner])
    return mission


def test_tasks_has_sections_marks_and_tags(planned: Mission) -> None:
    text = format_tasks(planned.state, "Plan")
    lines = text.splitlines()
    assert lines[0] == f"=== Plan (revision {planned.revision}) ==="
    alpha = lines.index("  alpha")
    assert lines[alpha + 1].startswith("    >> alpha-1")
    assert "go" in lines[alpha + 1]
    assert lines[alpha + 2].endswith(" blueprint")
    assert "barrier barrier-" in lines[alpha + 3]
    assert lines[lines.index("  charlie") + 1].endswith("blueprint (empty)")


def test_tasks_without_title_names_revision_and_library(planned: Mission) -> None:
    first = format_tasks(planned.state).splitlines()[0]
    assert first == f"mission at revision {planned.revision} (library unit_team)"


def test_tasks_shows_uploading(mission: Mission, drv: Any) -> None:
    drv.add("alpha")
    mission.synchronize("alpha")
    assert "uploading" in format_tasks(mission.state)


def test_tasks_with_statuses_adds_one_line_per_robot(planned: Mission) -> None:
    status = AgentStatus("alpha", link="up", last_heard=0.25, battery=0.5, executor_state="run")
    lines = format_tasks(planned.state, statuses={"alpha": status}).splitlines()
    assert lines[lines.index("  alpha") + 1] == (
        "    link up (heard 0.2 s ago), battery 50%, executor run"
    )
    assert lines[lines.index("  bravo") + 1] == "    link unknown"


def test_verbose_tasks_lists_parameters(planned: Mission) -> None:
    text = format_tasks(planned.state, verbose=True)
    assert "point=@Spot" in text
    assert "seconds=3" in text
    assert "speed=1.5" in text


def test_agent_status_line_with_telemetry() -> None:
    status = AgentStatus(
        "alpha",
        link="down",
        round_trip=0.012,
        commands_in_flight=2,
        wifi_signal=-61.0,
        pose=Pose(1.0, 2.5),
        in_coverage=False,
        waiting_on="bravo",
    )
    line = format_agent_status(status)
    assert line.startswith("link down (round trip 12 ms, 2 commands in flight)")
    assert "Wi-Fi out of range (-61 dBm)" in line and "at (1, 2.5, 0)" in line
    assert "out of coverage" in line and line.endswith("waiting on bravo")
    assert format_agent_status(None) == "link unknown"


@pytest.mark.parametrize(
    ("ptype", "value"),
    [
        (ParamType.BOOL, True),
        (ParamType.INT, -3),
        (ParamType.FLOAT, 1.25),
        (ParamType.FLOAT, 12.0),
        (ParamType.STRING, "fast"),
        (ParamType.LIST, [{"x": 0, "y": 1.5}]),
        (ParamType.DICT, {"a": [1, 2]}),
        (ParamType.POSE, Pose(3.0, 4.0, 0.0, 0.0, 0.0, 1.57)),
    ],
)
def test_format_value_reads_back_with_parse_text(ptype: ParamType, value: Any) -> None:
    parsed = parse_text(ptype, format_value(value), "p")
    if ptype is ParamType.POSE:
        parsed = Pose.from_any(parsed, "p")
    assert parsed == value


def test_markers_text(planned: Mission) -> None:
    assert format_markers(planned.state.markers) == (
        "Spot                     pose      (3, 4, 0) yaw 1.5"
    )
    assert format_markers([]) == "(no task markers)"
    area = TaskMarker("A", MarkerType.AREA, Pose(1.0, 1.0), (Pose(), Pose(1.0), Pose(0.0, 1.0)))
    assert "3 vertices around (1, 1, 0)" in format_markers([area])


def test_library_text_lists_agents_skills_and_schemas(library: Library) -> None:
    text = format_library(library)
    assert text.splitlines()[0] == "library unit_team"
    assert "alpha (dynamic, model walker)" in text
    assert "base (static, model station)" in text
    assert "    speed: float = 1 m/s, range 0.1..2" in text
    assert "    mode: string = fast, one of fast|slow" in text
    assert "marker area" in text
    only = format_library(library, "bravo")
    assert "alpha" not in only and "bravo (dynamic" in only


def test_mission_json_has_stable_keys(planned: Mission, library: Library) -> None:
    data = mission_to_json(planned.state, library, {"alpha": AgentStatus("alpha", link="up")})
    json.dumps(data)  # plain data only
    assert set(data) == {"revision", "library", "agents", "barriers", "markers"}
    assert data["revision"] == planned.revision
    assert [a["name"] for a in data["agents"]] == ["alpha", "bravo", "charlie", "base"]
    alpha = data["agents"][0]
    assert alpha["kind"] == "dynamic" and alpha["model"] == "walker"
    assert alpha["link"]["state"] == "up"
    assert data["agents"][1]["link"] is None
    first, scan, _ = alpha["skills"]
    assert {
        "id",
        "skill",
        "label",
        "status",
        "transfer",
        "resolution",
        "attempt",
        "params",
        "bindings",
        "status_text",
    } <= set(first)
    assert first["status"] == SkillStatus.RUNNING.name and first["label"] == "go"
    assert scan["bindings"] == {"point": "Spot"}
    assert scan["params"]["point"]["yaw"] == 1.5
    barrier = data["barriers"][0]
    assert barrier["skills"] == [scan["id"], data["agents"][1]["skills"][0]["id"]]
    assert barrier["agents"] == ["alpha", "bravo"]
    assert data["markers"][0] == {
        "name": "Spot",
        "type": "pose",
        "pose": {"x": 3.0, "y": 4.0, "z": 0.0, "roll": 0.0, "pitch": 0.0, "yaw": 1.5},
        "vertices": [],
    }


def test_mission_json_without_statuses_has_no_link(planned: Mission, library: Library) -> None:
    data = mission_to_json(planned.state, library)
    assert all("link" not in agent for agent in data["agents"])


def test_library_json(library: Library) -> None:
    data = library_to_json(library)
    json.dumps(data)
    alpha = data["agents"][0]
    assert alpha["name"] == "alpha" and alpha["kind"] == "dynamic"
    move = next(s for s in alpha["skills"] if s["name"] == "move")
    target, speed = move["parameters"]
    assert target["type"] == "pose" and target["marker"] == "pose"
    assert target["default"] == {"x": 0.0, "y": 0.0, "z": 0.0, "roll": 0.0, "pitch": 0.0, "yaw": 0}
    assert speed == {
        "name": "speed",
        "type": "float",
        "default": 1.0,
        "min": 0.1,
        "max": 2.0,
        "choices": [],
        "unit": "m/s",
        "description": "",
        "marker": None,
        "check": None,
    }
    assert data["agents"][3]["skills"] == []


def test_event_line_and_json(mission: Mission) -> None:
    event = mission.add_skill("alpha", "move")
    line = format_event(event)
    assert line.startswith("r1     SKILL_ADDED       alpha")
    assert line.endswith(event.summary)
    assert event_to_json(event) == {
        "revision": 1,
        "kind": "SKILL_ADDED",
        "agent": "alpha",
        "summary": event.summary,
        "stamp": event.stamp,
    }
