"""The marker node follows the library of the server it talks to.

A marker node that outlives its mission server and meets a new one with another library
(the drone called ``scout``) must draw that library's agents and send requests the new
server accepts, at once: not keep the old library and refuse every request.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from rosmc_server.ros.client import MissionClient
from tests.integration.markers_fixtures import (
    MarkerNodeProcess,
    Rviz,
    current,
    scout_library,
    wait_for,
)

pytest_plugins = ["tests.integration.server_fixtures"]


@pytest.fixture
def live_markers(client_node: Any, tmp_path: Path) -> Iterator[MarkerNodeProcess]:
    node = MarkerNodeProcess(dict(client_node.env), tmp_path / "markers.log")
    try:
        yield node
    finally:
        node.stop()
        print("--- markers_node ---\n" + "\n".join(node.log().splitlines()[-30:]))


def test_markers_follow_a_new_server_with_another_library(
    start_server: Any, live_markers: MarkerNodeProcess, tmp_path: Path
) -> None:
    first = start_server()
    rviz = Rviz()
    try:
        rviz.marker("robot/drone")
        # The node looks at the server once a second and at TF 2 s after the library came:
        # by then it has seen this server's process, and tells the next one from it.
        wait_for(lambda: "agents without TF" in live_markers.log(), "the node's first looks")
        first.stop()
        start_server(library=str(scout_library(tmp_path)))
        shown = wait_for(
            lambda: (m := rviz.markers()) and "robot/scout" in m and "robot/drone" not in m,
            "the new library's agents",
        )
        assert shown
        rviz.select_menu("robot/scout", "Add skill", "take_off")  # checked by the new library
        client = MissionClient(10.0)
        try:
            (skill,) = wait_for(lambda: list(current(client).task("scout")), "the scout's skill")
        finally:
            client.close()
        assert skill.skill == "take_off"
        assert "NotFound" not in live_markers.log()
    finally:
        rviz.close()
