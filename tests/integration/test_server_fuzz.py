"""Malformed requests to every operator service of a real mission server (hypothesis).

Every field of every request is drawn from its wire type, biased towards what breaks
servers: empty, unicode and very long text, huge integers, NaN and infinities, parameter
values whose type number and filled field disagree, invalid JSON, unknown or real ids.
For each request: no ServiceException (no handler raised), the server stays up, and
either the response carries an error code (never INTERNAL) and one sentence with the
mission unchanged, or it is a legitimate success whose revision is exactly one higher.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import pytest
import rosmc.msg as wire
import rosmc.srv as srv
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

pytest.register_assert_rewrite("tests.integration.server_fixtures")

from rosmc_server import interface  # noqa: E402
from tests.integration.server_fixtures import (  # noqa: E402
    Client,
    ServerProcess,
    accepted,
    assert_one_sentence,
    mission_key,
)

pytest_plugins = ["tests.integration.server_fixtures"]
pytestmark = pytest.mark.integration

E = wire.ErrorCode
PV = wire.ParameterValue
CURRENT = object()  # stands for the current revision, filled in at call time
# Requests that do not change the mission when they succeed.
NO_CHANGE = {"control", "set_lost_link_policy", "save_mission"}
FUZZED = [op for op in interface.SERVICES if op not in ("get_mission", "get_library")]
KNOWN_NAMES = [
    "drone",
    "science_rover",
    "manipulator_rover",
    "lander",
    "take_off",
    "navigate_to",
    "fly_over",
    "explore",
    "pick_box",
    "altitude",
    "target",
    "area",
    "speed",
    "box",
    "Site",
    "Zone",
    "continue",
    "hold",
    "safe_skill",
    "return_to_lander",
]
SETTINGS = settings(
    max_examples=40,
    deadline=None,
    database=None,
    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow],
)


# -- strategies by wire type --------------------------------------------------------------------
def texts(known: list[str]) -> st.SearchStrategy[str]:
    return st.one_of(
        st.sampled_from(known),
        st.just(""),
        st.text(max_size=24),
        st.text(st.characters(codec="utf-8"), min_size=1, max_size=8).map(lambda s: s * 997),
        st.sampled_from([" ", "\n", "\0", "drone\n", "Ω≈ç√", "'", "%s%n", "../../etc/passwd"]),
    )


FLOATS = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True),
    st.sampled_from([math.nan, math.inf, -math.inf, 0.0, -0.0, 1e308, 5.0, 12.0]),
)
JSON_TEXT = st.one_of(
    st.sampled_from(
        [
            "",
            "[",
            "{",
            "[{]",
            "NaN",
            "[NaN]",
            "[Infinity]",
            "null",
            "[1e999]",
            '[{"x": 1, "y": 2}]',
            '{"a": [1, 2]}',
            "[" * 5000 + "]" * 5000,
            '"text"',
            "[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]",
        ]
    ),
    st.text(max_size=40),
)
POSES = st.builds(wire.Pose6D, FLOATS, FLOATS, FLOATS, FLOATS, FLOATS, FLOATS)


def parameter_values(known: list[str]) -> st.SearchStrategy[Any]:
    return st.builds(
        PV,
        name=texts(KNOWN_NAMES),
        type=st.integers(0, 255),
        bool_value=st.booleans(),
        int_value=st.integers(-(2**63), 2**63 - 1),
        float_value=FLOATS,
        string_value=texts(["quick", "sample_box", "wifi_box"]),
        json_value=JSON_TEXT,
        pose_value=POSES,
        marker=st.one_of(st.just(""), st.just(""), texts(known)),
    )


def field_strategy(type_name: str, known: list[str], tmp: Path) -> st.SearchStrategy[Any]:
    """Values for one request field of ROS type ``type_name``."""
    strategies: dict[str, st.SearchStrategy[Any]] = {
        "string": texts(known),
        "bool": st.booleans(),
        "uint8": st.integers(0, 255),
        "int32": st.integers(-(2**31), 2**31 - 1),
        "uint32": st.one_of(st.integers(0, 2**32 - 1), st.integers(0, 5)),
        "uint64": st.one_of(st.just(CURRENT), st.just(CURRENT), st.integers(0, 2**64 - 1)),
        "float64": FLOATS,
        "string[]": st.lists(texts(known), max_size=6),
        "rosmc/ParameterValue[]": st.lists(parameter_values(known), max_size=4),
        "rosmc/Pose6D": POSES,
        "rosmc/Pose6D[]": st.lists(POSES, max_size=6),
        "rosmc/SkillMove[]": st.lists(
            st.builds(
                wire.SkillMove,
                skill_id=texts(known),
                index=st.one_of(st.integers(0, 2**32 - 1), st.integers(0, 12)),
            ),
            max_size=6,
        ),
        "rosmc/TaskMarker": st.builds(
            wire.TaskMarker,
            name=texts(known),
            type=st.integers(0, 255),
            pose=POSES,
            vertices=st.lists(POSES, max_size=6),
        ),
    }
    return strategies[type_name]


def paths(tmp: Path) -> st.SearchStrategy[str]:
    """Paths on the server's host, kept inside the test's directory (the server writes them)."""
    names = st.text(st.characters(codec="utf-8", exclude_characters="/\0"), min_size=1, max_size=40)
    return st.one_of(
        st.just(""),
        names.map(lambda n: str(tmp / n)),
        names.map(lambda n: str(tmp / "missing" / n)),
        st.just(str(tmp)),
        st.just(str(tmp / "a\0b")),
        st.just(str(tmp / ("x" * 300))),
    )


def requests(operation: str, known: list[str], tmp: Path) -> st.SearchStrategy[dict[str, Any]]:
    request_class = getattr(srv, interface.SERVICES[operation])._request_class
    fields = {}
    for name, type_name in zip(request_class.__slots__, request_class._slot_types, strict=True):
        if name == "path":
            fields[name] = paths(tmp)
        elif name == "document":
            fields[name] = st.one_of(st.just(""), st.sampled_from(DOCUMENTS), texts(known))
        else:
            fields[name] = field_strategy(type_name, known, tmp)
    return st.fixed_dictionaries(fields)


DOCUMENTS = [
    "rosmc_mission: 1\nlibrary: mars_sample_return\nrevision: 0\ntasks: {}\n",
    "rosmc_mission: 1\nlibrary: mars_sample_return\nrevision: -1\ntasks: {drone: []}\n",
    "!!python/object/apply:os.system ['true']",
    "rosmc_mission: !!python/name:os.system\n",
    "{a: [1, 2",
    "- just\n- a list\n",
    "rosmc_mission: 1\nlibrary: mars_sample_return\nrevision: 0\n"
    "tasks: {drone: [{id: x, skill: take_off, label: x, params: {altitude: .nan},\n"
    "  status: IDLE}]}\n",
    "rosmc_mission: 1\nlibrary: mars_sample_return\nrevision: 0\n"
    "tasks: {drone: [{id: x, skill: take_off, label: x, params: {}, status: RUNNING}]}\n",
    "a: &a [*a]\n",
    "x: " + "[" * 3000 + "]" * 3000 + "\n",
]


# -- the target -----------------------------------------------------------------------------------
@pytest.fixture
def target(module_server: ServerProcess, client: Client) -> Any:
    """The module's server with a small mission whose ids the fuzzer may hit.

    A fuzzed synchronize may leave skills waiting for a robot, which no new mission
    can clear: then the server starts over.
    """
    if not module_server.alive:
        module_server.start()
    response = client.call("new_mission", base_revision=client.revision(), keep_markers=False)
    if response.error_code != E.NONE:
        module_server.kill9()
        module_server.start()
        client.close()
    rev = client.revision()

    def do(operation: str, **fields: Any) -> Any:
        nonlocal rev
        response = accepted(client.call(operation, base_revision=rev, **fields))
        rev = response.revision
        return response

    square = [wire.Pose6D(x=0), wire.Pose6D(x=4), wire.Pose6D(x=4, y=4)]
    do("add_task_marker", marker=wire.TaskMarker(name="Site", type=1, pose=wire.Pose6D(x=1)))
    do("add_task_marker", marker=wire.TaskMarker(name="Zone", type=2, vertices=square))
    known = ["Site", "Zone"]
    for agent, skill in (
        ("drone", "take_off"),
        ("drone", "navigate_to"),
        ("science_rover", "explore"),
        ("manipulator_rover", "pick_box"),
    ):
        known.append(do("add_skill", agent=agent, skill=skill, index=-1).skill_id)
    known.append(do("add_barrier", skill_ids=[known[2], known[4]]).barrier_id)
    return module_server, client, known + KNOWN_NAMES


def check(server: ServerProcess, client: Client, operation: str, fields: dict[str, Any]) -> None:
    before = client.mission()
    filled = {k: before.revision if v is CURRENT else v for k, v in fields.items()}
    response = client.call(operation, **filled)  # a ServiceException fails the test
    after = client.mission()
    assert server.alive
    if response.error_code != E.NONE:
        assert response.error_code in (E.INVALID, E.NOT_FOUND, E.RULE, E.CONFLICT, E.UNAVAILABLE), (
            response.error_code,
            response.error,
        )
        assert_one_sentence(response.error)
        assert mission_key(after) == mission_key(before), f"{operation} changed the mission"
        assert response.revision == before.revision
    elif operation in NO_CHANGE:
        assert response.error == ""
        assert mission_key(after) == mission_key(before)
    else:
        assert response.error == ""
        assert after.revision == response.revision == before.revision + 1


@pytest.mark.parametrize("operation", FUZZED)
def test_fuzzed_requests_are_refused_cleanly(target: Any, operation: str, tmp_path: Path) -> None:
    server, client, known = target

    @SETTINGS
    @given(fields=requests(operation, known, tmp_path))
    def fuzz(fields: dict[str, Any]) -> None:
        check(server, client, operation, fields)

    fuzz()
    assert server.alive
    assert "Traceback" not in server.log(), server.log()[-4000:]
    assert "[ERROR]" not in server.log(), server.log()[-4000:]
