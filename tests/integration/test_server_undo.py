"""The mission server's undo service: journaled like any change, and still there after a crash.

A real master and ``mission_server`` process; the Python client calls ``undo_edit``.
The server is killed with SIGKILL and resumed from its journal: the undone edit stays
undone, and the edits before it can still be undone (or redone) in the resumed server.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import pytest

from rosmc_server.core import RuleViolation
from rosmc_server.ros.client import MissionClient
from tests.integration.server_fixtures import ServerProcess

pytest_plugins = ["tests.integration.server_fixtures"]


def test_undo_is_journaled_and_survives_a_crash(
    start_server: Callable[..., ServerProcess], tmp_path: Path
) -> None:
    journal = tmp_path / "undo.mcap"
    server = start_server("undo", journal=journal)
    with MissionClient(timeout=10.0) as client:
        client.get_mission()
        added = client.add_skill("drone", "take_off", {"altitude": 12.0})
        edited = client.edit_skill(added.skill_id, {"altitude": 20.0})
        undone = client.undo_edit()
        assert undone.revision == edited.revision + 1
        assert undone.summary == (
            f"undo of revision {edited.revision} ('{added.skill_id}' (take_off) edited)"
        )
        assert client.skill(added.skill_id).params["altitude"] == 12.0
    server.kill9()

    start_server("undo", journal=journal, resume=True)
    with MissionClient(timeout=10.0) as client:
        mission = client.get_mission()
        assert mission.revision == undone.revision
        assert client.skill(added.skill_id).params["altitude"] == 12.0
        redone = client.undo_edit(undone.revision)  # the resumed server still knows the undo
        assert client.skill(added.skill_id).params["altitude"] == 20.0
        with pytest.raises(RuleViolation) as refused:  # the skill changed since it was added
            client.undo_edit(added.revision)
        assert str(refused.value) == (
            f"skill '{added.skill_id}' was changed since revision {added.revision}; "
            "undo that change first"
        )
        assert client.get_mission().revision == redone.revision
