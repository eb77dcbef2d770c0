"""The ``rosmc_command`` window started as a process: first rows early, then every row.

A real master and mission server hold a mission of 20 robots x 500 skills. The real entry
script starts the window (offscreen Qt) with ``--startup-report``; the report says, in the
order the stages ended, what the window had shown: its first rows were painted while
robots' columns were still to come, then every column held every skill. The modules the
window had imported by then leave out what the first paint does not need.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from bench._missions import library_yaml, mission_yaml
from rosmc_rqt_command.qt.task_widget import FIRST_COLUMNS
from tests import conftest
from tests.integration.executor_fixtures import Operator, RosmcSystem

AGENTS, SKILLS = 20, 500
# Imported only when the operator asks for them (a replay, a recording), never at the start.
NOT_AT_START = (
    "numpy",
    "mcap",
    "rosmc_server.recording",
    "rosmc_rqt_command.ros_replay",
)


def read_report(path: Path) -> dict[str, dict[str, Any]]:
    """The stages written so far, by name (complete lines only)."""
    text = path.read_text() if path.exists() else ""
    return {
        line["stage"]: line
        for line in (json.loads(raw) for raw in text.splitlines() if raw.endswith("}"))
    }


def test_the_window_paints_first_rows_then_every_row(
    ros_master: Any, tmp_path: Path, launch_process: Any
) -> None:
    library = tmp_path / "library.yaml"
    library.write_text(library_yaml(AGENTS))
    system = RosmcSystem(ros_master.env, tmp_path / "system", library)
    system.start_server()
    operator = Operator(timeout=60.0)
    try:
        revision = operator.call("get_mission").mission.revision
        operator.call("load_mission", base_revision=revision, document=mission_yaml(AGENTS, SKILLS))
        report_path = tmp_path / "startup.jsonl"
        env = dict(ros_master.env, QT_QPA_PLATFORM="offscreen")
        window = launch_process(
            ["rosmc_command", "--startup-report", str(report_path)], env=env, name="window"
        )
        report = conftest.wait_until(
            lambda: (r := read_report(report_path)).get("all") and r,
            120,
            "the window to show the whole mission",
        )
        assert window.poll() is None, window.log()
    finally:
        operator.close()
        system.close()

    order = sorted(report, key=lambda stage: report[stage]["t"])
    assert order.index("main") < order.index("window")
    assert order.index("node") < order.index("snapshot") < order.index("rows")
    assert order[-1] == "all"
    # The first paint showed the columns that fit, with their rows; the rest came after.
    first = report["rows"]
    assert FIRST_COLUMNS <= first["columns"] < AGENTS
    assert first["rows"] == first["columns"] * SKILLS
    assert (report["all"]["columns"], report["all"]["rows"]) == (AGENTS, AGENTS * SKILLS)
    loaded = set(report["all"]["modules"])
    assert "rosmc_rqt_command.qt.command_widget" in loaded
    assert [module for module in loaded if module.startswith(NOT_AT_START)] == []
