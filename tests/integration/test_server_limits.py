"""The documented input limits (rosmc_server/core/validation.py), through the real services.

Each refusal is one sentence with the INVALID code, leaves the mission as it was, and the
server serves on.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest
import rosmc.msg as wire
from rosmc.msg import ErrorCode

pytest.register_assert_rewrite("tests.integration.server_fixtures")

from rosmc_server.core.files.mission_text import digest_line  # noqa: E402
from rosmc_server.core.validation import MAX_CORNERS, MAX_SKILLS  # noqa: E402
from tests.integration.server_fixtures import Client, ServerProcess, mission_key  # noqa: E402

pytest_plugins = ["tests.integration.server_fixtures"]


def refused(response: object, *phrases: str) -> str:
    """The sentence of an INVALID refusal, checked to be one line holding ``phrases``."""
    assert response.error_code == ErrorCode.INVALID, response  # type: ignore[attr-defined]
    sentence = str(response.error)  # type: ignore[attr-defined]
    assert "\n" not in sentence and sentence.count(". ") == 0, sentence
    for phrase in phrases:
        assert phrase in sentence, sentence
    return sentence


def resigned(document: str, old: str, new: str) -> str:
    """``document`` with ``old`` replaced by ``new`` and its digest line made to match."""
    body = document[: document.rindex("# sha256")]
    assert old in body, body
    body = body.replace(old, new, 1)
    return body + digest_line(body)


def saved_document(client: Client) -> str:
    """The mission as a document (SaveMission without a path)."""
    response = client.call("save_mission", path="", return_document=True)
    assert response.error_code == ErrorCode.NONE, response.error
    return str(response.document)


def area(name: str, corners: int) -> wire.TaskMarker:
    """An area marker with ``corners`` corners along a zigzag."""
    vertices = [wire.Pose6D(x=float(i), y=float(i % 7)) for i in range(corners)]
    return wire.TaskMarker(name=name, type=wire.TaskMarker.AREA, vertices=vertices)


def test_a_lone_surrogate_in_a_loaded_label_is_refused(
    fresh: Client, module_server: ServerProcess
) -> None:
    added = fresh.call(
        "add_skill", base_revision=fresh.revision(), agent="drone", skill="take_off", label="hello"
    )
    assert added.error_code == ErrorCode.NONE, added.error
    before = fresh.mission()
    # JSON flow lines carry escapes; \ud800 alone decodes to a lone surrogate, not text.
    document = resigned(saved_document(fresh), '"label": "hello"', '"label": "a\\ud800b"')
    response = fresh.call("load_mission", base_revision=before.revision, document=document)
    refused(response, "a label", "printable characters")
    assert mission_key(fresh.mission()) == mission_key(before) and module_server.alive


def test_an_area_of_too_many_corners_is_refused_on_every_path(
    fresh: Client, module_server: ServerProcess
) -> None:
    before = fresh.mission()
    too_many = MAX_CORNERS + 1
    big = area("Big", too_many)
    response = fresh.call("add_task_marker", base_revision=before.revision, marker=big)
    refused(response, f"at most {MAX_CORNERS} corners", f"has {too_many}")
    ok = fresh.call("add_task_marker", base_revision=before.revision, marker=area("Zone", 3))
    assert ok.error_code == ErrorCode.NONE, ok.error
    moved = fresh.call(
        "move_task_marker",
        base_revision=ok.revision,
        name="Zone",
        vertices=area("Zone", 200_000).vertices,
    )
    refused(moved, f"at most {MAX_CORNERS} corners", "has 200000")
    current = fresh.mission()
    corners = [
        {"x": float(i), "y": float(i % 7), "z": 0.0, "roll": 0.0, "pitch": 0.0, "yaw": 0.0}
        for i in range(200_000)
    ]
    document = saved_document(fresh)
    line = next(line for line in document.splitlines() if '"name": "Zone"' in line)
    entry = json.loads(line[2:])
    entry["vertices"] = corners
    loaded = fresh.call(
        "load_mission",
        base_revision=current.revision,
        document=resigned(document, line, "- " + json.dumps(entry)),
    )
    refused(loaded, "markers[0]", f"at most {MAX_CORNERS} corners")
    assert mission_key(fresh.mission()) == mission_key(current) and module_server.alive


def test_a_mission_of_too_many_skills_is_refused(fresh: Client) -> None:
    added = fresh.call("add_skill", base_revision=fresh.revision(), agent="drone", skill="take_off")
    assert added.error_code == ErrorCode.NONE, added.error
    document = saved_document(fresh)
    line = next(line for line in document.splitlines() if '"skill": "take_off"' in line)
    indent, entry_text = line.split("- ", 1)
    entry = json.loads(entry_text)
    lines = []
    for i in range(MAX_SKILLS + 1):
        entry["id"] = f"s-{i}"
        lines.append(f"{indent}- {json.dumps(entry)}")
    flood = resigned(document, line, "\n".join(lines))
    response = fresh.call("load_mission", base_revision=added.revision, document=flood)
    refused(response, "tasks", f"at most {MAX_SKILLS} skills", f"this one {MAX_SKILLS + 1}")
    assert fresh.revision() == added.revision


def test_a_file_name_with_a_line_break_is_refused(
    fresh: Client, module_server: ServerProcess
) -> None:
    mission_dir = Path(str(module_server.params["mission_dir"]))
    before = set(mission_dir.iterdir())
    response = fresh.call("save_mission", path="x\ny.yaml")
    refused(response, "a mission file path must be one line", "'x\\ny.yaml'")
    assert set(mission_dir.iterdir()) == before
    loaded = fresh.call("load_mission", base_revision=fresh.revision(), path="x\ny.yaml")
    refused(loaded, "a mission file path must be one line")
