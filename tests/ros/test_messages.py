"""Every rosmc message and service type is generated and survives serialize → deserialize.

No master is needed: genpy serializes into ``BytesIO`` and deserializes from ``bytes``.
"""

from __future__ import annotations

import json
import math
import re
from io import BytesIO
from pathlib import Path
from typing import Any

import genpy
import pytest
import rosmc.msg as m
import rosmc.srv as s

REPO_ROOT = Path(__file__).resolve().parents[2]
MSG_NAMES = sorted(path.stem for path in (REPO_ROOT / "rosmc_msgs" / "msg").glob("*.msg"))
SRV_NAMES = sorted(path.stem for path in (REPO_ROOT / "rosmc_msgs" / "srv").glob("*.srv"))
PRIMITIVE_VALUES: dict[str, Any] = {
    "bool": True,
    "int8": -8,
    "uint8": 8,
    "int16": -16,
    "uint16": 16,
    "int32": -32,
    "uint32": 32,
    "int64": -(2**40),
    "uint64": 2**40,
    "float32": 0.5,  # exactly representable in 32 bits
    "float64": 1.0 / 3.0,
    "string": "Steinprobe ü #1",
}


# Short names for the constant holders used below.
P = m.ParameterValue
S = m.SkillStatus
T = m.TaskMarker
E = m.MissionEvent
L = m.LinkState


def round_trip(msg: genpy.Message) -> genpy.Message:
    """Serialize ``msg`` and deserialize the bytes into a new instance of its class."""
    buffer = BytesIO()
    msg.serialize(buffer)
    data = buffer.getvalue()
    copy = type(msg)()
    copy.deserialize(data)
    again = BytesIO()
    copy.serialize(again)
    assert again.getvalue() == data, "re-serializing gives the same bytes"
    return copy


def filled(cls: type[genpy.Message], depth: int = 0) -> genpy.Message:
    """An instance of ``cls`` with every field set to a non-default value (arrays of two)."""
    msg = cls()
    for name, slot_type in zip(cls.__slots__, cls._slot_types, strict=True):
        setattr(msg, name, _value(slot_type, depth))
    return msg


def _value(slot_type: str, depth: int) -> Any:
    match = re.fullmatch(r"(.+)\[(\d*)\]", slot_type)
    if match:
        base, size = match.group(1), match.group(2)
        count = int(size) if size else 2
        if base in ("uint8", "char"):
            return bytes(range(1, count + 1))
        return [_value(base, depth) for _ in range(count)]
    if slot_type in PRIMITIVE_VALUES:
        return PRIMITIVE_VALUES[slot_type]
    if slot_type == "time":
        return genpy.Time(1_700_000_000, 123_456_789)
    if slot_type == "duration":
        return genpy.Duration(3, 500)
    if slot_type == "Header":
        slot_type = "std_msgs/Header"
    nested = genpy.message.get_message_class(slot_type)
    assert nested is not None, f"unknown field type {slot_type}"
    return filled(nested, depth + 1)


def stamp(seconds: int) -> genpy.Time:
    return genpy.Time(1_700_000_000 + seconds, 250_000_000)


# ---------------------------------------------------------------- every type, generically


def test_every_definition_file_is_found() -> None:
    assert len(MSG_NAMES) >= 20 and len(SRV_NAMES) >= 15


@pytest.mark.parametrize("name", MSG_NAMES)
def test_message_type_imports_and_round_trips(name: str) -> None:
    cls = getattr(m, name)
    assert cls._type == f"rosmc/{name}"
    assert round_trip(cls()) == cls()
    full = filled(cls)
    assert round_trip(full) == full


@pytest.mark.parametrize("name", SRV_NAMES)
def test_service_type_imports_and_round_trips(name: str) -> None:
    service = getattr(s, name)
    request_cls = getattr(s, f"{name}Request")
    response_cls = getattr(s, f"{name}Response")
    assert service._type == f"rosmc/{name}"
    assert service._request_class is request_cls
    assert service._response_class is response_cls
    for cls in (request_cls, response_cls):
        assert round_trip(cls()) == cls()
        full = filled(cls)
        assert round_trip(full) == full


# ---------------------------------------------------------------- a realistic mission snapshot


def param(name: str, kind: int, **value: Any) -> m.ParameterValue:
    return m.ParameterValue(name=name, type=kind, **value)


def every_parameter_type() -> list[m.ParameterValue]:
    return [
        param("cameras_on", P.BOOL, bool_value=True),
        param("passes", P.INT, int_value=-3),
        param("speed", P.FLOAT, float_value=0.75),
        param("note", P.STRING, string_value="avoid the dune"),
        param("waypoints", P.LIST, json_value=json.dumps([[1.0, 2.0], [3.5, -4.0]])),
        param("options", P.DICT, json_value=json.dumps({"mode": "scan", "bands": [1, 2]})),
        param(
            "target",
            P.POSE,
            pose_value=m.Pose6D(x=12.5, y=-3.0, z=0.0, roll=0.0, pitch=0.1, yaw=1.57),
            marker="rss_1",
        ),
    ]


def skill(skill_id: str, agent: str, name: str, status: int, **fields: Any) -> m.Skill:
    return m.Skill(
        id=skill_id,
        agent=agent,
        skill=name,
        label=fields.pop("label", name),
        parameters=fields.pop("parameters", every_parameter_type()),
        status=m.SkillStatus(value=status),
        **fields,
    )


def markers() -> list[m.TaskMarker]:
    square = [m.Pose6D(x=x, y=y) for x, y in ((0, 0), (4, 0), (4, 4), (0, 4))]
    return [
        T(name="lander", type=T.POSITION, pose=m.Pose6D(x=0.5, y=0.5, z=0.2)),
        T(name="rss_1", type=T.POSE, pose=m.Pose6D(x=12.5, y=-3.0, yaw=1.57)),
        T(name="survey", type=T.AREA, pose=m.Pose6D(x=2.0, y=2.0), vertices=square),
    ]


def mission_snapshot() -> m.Mission:
    scout = [
        skill("s1", "scout", "take_off", S.SUCCESS, attempt=1, started=10.0, finished=14.5),
        skill("s2", "scout", "explore_area", S.RUNNING, attempt=1, started=15.0, timeout=120.0),
        skill("s3", "scout", "land", S.IDLE_SYNCHRONIZED, transfer=m.Skill.TRANSFER_UPLOADING),
        skill("s4", "scout", "observe", S.IDLE, label="observe RSS 1"),
    ]
    rover = [
        skill(
            "r1",
            "rover",
            "drive_to",
            S.FAILURE,
            attempt=1,
            resolution=m.Skill.RESOLUTION_RETRIED,
            status_text="wheel slip",
        ),
        skill("r2", "rover", "drive_to", S.SYNCWAITING, attempt=2, max_retries=2),
        skill("r3", "rover", "identify_stone", S.IDLE),
    ]
    return m.Mission(
        revision=42,
        stamp=stamp(0),
        library="mars_team",
        tasks=[m.AgentTask(agent="scout", skills=scout), m.AgentTask(agent="rover", skills=rover)],
        barriers=[
            m.Barrier(id="b1", skill_ids=["s3", "r2"], agents=["scout", "rover"]),
            m.Barrier(id="b2", skill_ids=["s4", "r3"], agents=["scout", "rover"]),
        ],
        markers=markers(),
    )


def test_mission_snapshot_round_trips() -> None:
    mission = mission_snapshot()
    copy = round_trip(mission)
    assert copy == mission
    assert [task.agent for task in copy.tasks] == ["scout", "rover"]
    kinds = {p.type for task in copy.tasks for sk in task.skills for p in sk.parameters}
    assert kinds == {P.BOOL, P.INT, P.FLOAT, P.STRING, P.LIST, P.DICT, P.POSE}
    assert {marker.type for marker in copy.markers} == {
        m.TaskMarker.POSITION,
        m.TaskMarker.POSE,
        m.TaskMarker.AREA,
    }
    by_name = {p.name: p for p in copy.tasks[0].skills[0].parameters}
    assert json.loads(by_name["waypoints"].json_value) == [[1.0, 2.0], [3.5, -4.0]]
    assert json.loads(by_name["options"].json_value) == {"mode": "scan", "bands": [1, 2]}
    assert by_name["target"].pose_value.yaw == pytest.approx(1.57)
    assert by_name["target"].marker == "rss_1"
    assert copy.stamp == stamp(0)


def test_mission_event_round_trips() -> None:
    mission = mission_snapshot()
    event = E(
        revision=43,
        stamp=stamp(1),
        kind=E.SKILL_ADDED,
        agent="rover",
        summary="Added identify_stone to rover.",
        put_skills=[m.PlacedSkill(index=3, skill=mission.tasks[1].skills[2])],
        removed_skill_ids=["r9"],
        order_agent="rover",
        blueprint_order=["r3", "r4"],
        put_barriers=[mission.barriers[1]],
        removed_barrier_ids=["b0"],
        put_markers=[mission.markers[2]],
        removed_marker_names=["old"],
        moves=[m.SkillMove(skill_id="r4", index=2), m.SkillMove(skill_id="r3", index=3)],
    )
    assert round_trip(event) == event
    replaced = E(revision=44, stamp=stamp(2), kind=E.MISSION_REPLACED, summary="Loaded.")
    assert round_trip(replaced) == replaced


def test_robot_link_messages_round_trip() -> None:
    mission = mission_snapshot()
    rover = mission.tasks[1].skills
    command = m.RobotCommand(
        agent="rover",
        seq=7,
        stamp=stamp(3),
        type=m.RobotCommand.UPLOAD,
        skills=rover[1:],
        skill_ids=[sk.id for sk in rover[1:]],
        barriers=mission.barriers,
        argument=json.dumps({"lost_link": "hold"}),
    )
    ack = m.RobotAck(
        agent="rover",
        seq=7,
        stamp=stamp(4),
        result=m.RobotAck.PARTIAL,
        accepted_ids=["r2"],
        rejected_ids=["r3"],
        rejection_reasons=["unknown skill"],
        queue_hash="9f2c",
    )
    report = m.RobotReport(
        agent="rover",
        seq=11,
        stamp=stamp(5),
        skill_id="r2",
        status=m.SkillStatus(value=m.SkillStatus.RUNNING),
        attempt=2,
        status_text="driving",
        started=20.25,
    )
    snapshot = m.ExecutorSnapshot(
        agent="rover",
        stamp=stamp(6),
        last_command_seq=7,
        last_report_seq=11,
        queue_hash="9f2c",
        queue=rover,
        state="running",
        active_skill_id="r2",
        waiting_on="scout",
        policy=m.LostLinkPolicy(kind=m.LostLinkPolicy.HOLD, after=30.0, acted="held"),
    )
    signal = m.BarrierSignal(
        agent="rover", barrier_id="b1", skill_id="r2", kind=m.BarrierSignal.READY, stamp=stamp(7)
    )
    for msg in (command, ack, report, snapshot, signal, m.ReportAck(agent="rover", seq=11)):
        assert round_trip(msg) == msg


def telemetry(agent: str, battery: float) -> m.Telemetry:
    return m.Telemetry(
        agent=agent,
        stamp=stamp(8),
        frame_id="map",
        pose=m.Pose6D(x=1.0, y=2.0, yaw=0.5),
        battery=battery,
        wifi_signal=-61.5,
        in_coverage=True,
    )


def test_agent_states_round_trip() -> None:
    states = m.AgentStates(
        stamp=stamp(9),
        revision=42,
        agents=[
            m.AgentState(
                agent=agent,
                telemetry=telemetry(agent, 0.75),
                link=L(
                    state=L.UP,
                    last_heard=0.2,
                    round_trip=0.004,
                    commands_in_flight=1,
                    queue_hash="9f2c",
                    robot_queue_hash="9f2c",
                ),
                current_skill_id=f"{agent[0]}2",
                current_status=m.SkillStatus(value=m.SkillStatus.RUNNING),
                executor_state="running",
            )
            for agent in ("scout", "rover")
        ],
    )
    assert round_trip(states) == states


def test_nan_telemetry_survives() -> None:
    """Agents without a battery report NaN; it must arrive as NaN."""
    copy = round_trip(telemetry("lander", math.nan))
    assert math.isnan(copy.battery)


def test_library_round_trips() -> None:
    spec = m.ParameterSpec(
        name="speed",
        type=P.FLOAT,
        default_value=param("speed", P.FLOAT, float_value=0.5),
        has_min=True,
        min=0.0,
        has_max=True,
        max=2.0,
        unit="m/s",
        description="Cruise speed.",
    )
    target = m.ParameterSpec(name="target", type=P.POSE, marker_type="POSE")
    library = m.Library(
        name="mars_team",
        agents=[
            m.AgentSpec(name="rover", kind=m.AgentSpec.DYNAMIC, model="science_rover"),
            m.AgentSpec(name="lander", kind=m.AgentSpec.STATIC, model="lander"),
        ],
        skill_sets=[
            m.SkillSet(
                model="science_rover",
                skills=[
                    m.SkillSpec(name="drive_to", parameters=[spec, target], estimated_duration=60)
                ],
            )
        ],
    )
    assert round_trip(library) == library
    response = s.GetLibraryResponse(library=library)
    assert round_trip(response) == response


def test_operator_service_round_trips() -> None:
    mission = mission_snapshot()
    request = s.AddSkillRequest(
        base_revision=42,
        agent="rover",
        skill="drive_to",
        index=-1,
        parameters=every_parameter_type(),
        timeout=90.0,
        max_retries=1,
    )
    response = s.AddSkillResponse(revision=43, error_code=m.ErrorCode.NONE, error="", skill_id="r4")
    rejected = s.SynchronizeResponse(
        revision=42, error_code=m.ErrorCode.CONFLICT, error="The mission changed; fetch it."
    )
    get = s.GetMissionResponse(mission=mission)
    for msg in (request, response, rejected, get, s.GetMissionRequest()):
        assert round_trip(msg) == msg
