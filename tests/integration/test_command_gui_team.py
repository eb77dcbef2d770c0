"""The command GUI with the 20-robot team against a real server and real executors.

A real rosmaster, the mission server with the 20 robots of
``rosmc_sim/scenarios/twenty_robots.yaml`` and the executors of two of them (the other
eighteen are never heard: out of contact). The real command window (offscreen Qt, 1600x1000)
follows; the operator scrolls to every robot, makes the columns compact and narrows the team
with the mouse and the keyboard.
"""

from __future__ import annotations

import os
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
import yaml

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")

from python_qt_binding.QtCore import Qt
from python_qt_binding.QtTest import QTest
from python_qt_binding.QtWidgets import QApplication

from rosmc_rqt_command.qt.command_widget import CommandWidget
from rosmc_rqt_command.standalone import build
from rosmc_sim.core.scenario import load_scenario
from tests import conftest
from tests.integration.executor_fixtures import Operator, RosmcSystem
from tests.team_gui import click, columns, on_screen, settle, step_right, team, tick
from tests.team_twenty import SCENARIO, twenty_robot_library_data

LINKED = ("drone_3", "manipulator_rover_7")  # robots with an executor running


@pytest.fixture
def window(ros_master: Any, tmp_path: Path) -> Iterator[tuple[CommandWidget, Operator]]:
    """Server, two executors and the command window following them at 1600x1000."""
    library = tmp_path / "mars_twenty_robots.yaml"
    library.write_text(yaml.safe_dump(twenty_robot_library_data(), sort_keys=False))
    system = RosmcSystem(ros_master.env, tmp_path / "system", library)
    system.start_server()
    for agent in LINKED:
        system.start_executor(agent)
    operator = Operator()
    operator.wait_links(LINKED)
    app = QApplication.instance() or QApplication([])
    widget, bridge = build(timeout=3.0)
    widget.resize(1600, 1000)
    widget.show()
    conftest.wait_until(
        lambda: widget.view.loaded and widget.view.library and len(columns(widget)) == 20,
        30,
        "the 20-robot mission shown",
        pause=conftest.qt_pause,
    )
    try:
        yield widget, operator
    finally:
        bridge.close()
        widget.close()
        widget.deleteLater()
        app.processEvents()
        operator.close()
        system.close()


def test_twenty_robots_scroll_compact_and_filter(window: Any) -> None:
    widget, operator = window
    robots = list(columns(widget))
    assert robots == [robot.name for robot in load_scenario(SCENARIO).robots]
    for robot in robots:
        operator.add(robot, "navigate_to")
    conftest.wait_until(
        lambda: all(c.blueprint_table.section.rows for c in columns(widget).values()),
        20,
        "every robot's task shown",
        pause=conftest.qt_pause,
    )
    settle(widget)
    # Every robot can be reached with the scroll bar.
    wide = on_screen(widget)
    seen = list(wide)
    bar = widget.tasks.horizontalScrollBar()
    while bar.value() < bar.maximum():
        step_right(widget)
        seen += [agent for agent in on_screen(widget) if agent not in seen]
    assert seen == robots
    bar.setValue(0)
    # Compact: more columns at once.
    click(widget, "team_compact")
    assert len(on_screen(widget)) > len(wide)
    # Out of contact: the eighteen robots never heard.
    click(widget, "team_status_out_of_contact")
    conftest.wait_until(
        lambda: team(widget).visible() == [r for r in robots if r not in LINKED],
        20,
        "only the robots not heard",
        pause=conftest.qt_pause,
    )
    # A name typed, and one robot unticked in the list.
    click(widget, "team_status_all")
    QTest.mouseClick(team(widget).text, Qt.LeftButton)
    QTest.keyClicks(team(widget).text, "rover_7")
    settle(widget)
    assert team(widget).visible() == ["science_rover_7", "manipulator_rover_7"]
    tick(widget, "science_rover_7")
    assert team(widget).visible() == ["manipulator_rover_7"]
    assert on_screen(widget) == ["manipulator_rover_7"]
    assert len(operator.mission().task("drone_1")) == 1  # filtering changed nothing
