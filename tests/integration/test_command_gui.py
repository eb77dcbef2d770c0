"""The command GUI driven like an operator: real widget, real master, server and executors.

Every step is a click, a key press, a menu choice or a drop on the real widget (offscreen
Qt); after each, the test asserts what the mission server holds (through its services)
and what the widget's rows show once the live update arrived.
"""

from __future__ import annotations

import math
import os
import subprocess
import sys
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")

from python_qt_binding.QtCore import QModelIndex, Qt, QTimer
from python_qt_binding.QtGui import QContextMenuEvent
from python_qt_binding.QtTest import QTest
from python_qt_binding.QtWidgets import QApplication, QMessageBox

from rosmc_rqt_command.core import presentation
from rosmc_rqt_command.qt.command_widget import CommandWidget
from rosmc_rqt_command.qt.policy_dialog import PolicyDialog
from rosmc_rqt_command.qt.section_table import SectionTable
from rosmc_rqt_command.qt.task_model import SKILL, STATUS, TAG
from rosmc_rqt_command.ros_bridge import RosBridge
from rosmc_rqt_command.standalone import build
from rosmc_server.core import (
    LostLinkKind,
    LostLinkPolicy,
    LostLinkTrigger,
    MarkerType,
    Pose,
    SkillStatus,
    TaskMarker,
)
from rosmc_server.ros.client import MissionClient
from tests import conftest
from tests.integration.executor_fixtures import REPO_ROOT, Operator, RosmcSystem

S = SkillStatus
LIBRARY = """
rosmc_library: 1
name: command_team
models:
  tester:
    skills:
      wait:
        duration: 1
        parameters:
          duration: {type: float, default: 0.2, min: 0.0, max: 3600.0, unit: s}
      probe:
        description: Work, then fail if asked.
        duration: 1
        parameters:
          duration: {type: float, default: 0.2, min: 0.0, max: 3600.0, unit: s}
          fail: {type: bool, default: false}
          repeats: {type: int, default: 1, min: 1, max: 10}
          mode: {type: string, default: quick, choices: [quick, standard, detailed]}
          note: {type: string, default: ""}
          tags: {type: list, default: []}
          extra: {type: dict, default: {}}
          target: {type: pose, default: {x: 0.0, y: 0.0}, marker: pose}
          area: {type: list, default: [{x: 0, y: 0}, {x: 1, y: 0}, {x: 1, y: 1}], marker: area}
agents:
  r1: {kind: dynamic, model: tester}
  r2: {kind: dynamic, model: tester}
"""
AGENTS = ("r1", "r2")


# -- helpers -------------------------------------------------------------------------------
def wait_until(condition: Callable[[], Any], timeout: float, what: str) -> Any:
    """Run the Qt event loop until ``condition()`` is truthy; fail after ``timeout``."""
    return conftest.wait_until(condition, timeout, what, pause=conftest.qt_pause)


class Gui:
    """The widget and the operator's hands."""

    def __init__(self, widget: CommandWidget, bridge: RosBridge) -> None:
        self.widget = widget
        self.bridge = bridge

    def column(self, agent: str) -> Any:
        return self.widget.tasks.columns[agent]

    def table(self, agent: str, blueprint: bool) -> SectionTable:
        column = self.column(agent)
        return column.blueprint_table if blueprint else column.synced_table

    def rows(self, agent: str, blueprint: bool) -> list[Any]:
        return self.table(agent, blueprint).section.rows

    def cell(self, agent: str, blueprint: bool, row: int, column: int, role: int) -> Any:
        model = self.table(agent, blueprint).section
        return model.data(model.index(row, column), role)

    def click_row(
        self, agent: str, blueprint: bool, row: int, modifier: Any = Qt.NoModifier
    ) -> None:
        table = self.table(agent, blueprint)
        rect = table.visualRect(table.section.index(row, SKILL))
        QTest.mouseClick(table.viewport(), Qt.LeftButton, modifier, rect.center())

    def click(self, name: str) -> None:
        button = self.widget.findChild(object, name)
        assert button is not None, name
        assert button.isEnabled(), f"{name} is disabled"
        QTest.mouseClick(button, Qt.LeftButton)

    def add(self, agent: str, skill: str) -> str:
        before = len(self.rows(agent, True))
        menu = self.column(agent).add_menu
        action = next(a for a in menu.actions() if a.text() == skill)
        action.trigger()  # the Add menu's entry, as a click on it does
        wait_until(lambda: len(self.rows(agent, True)) == before + 1, 30, f"{skill} on {agent}")
        return str(self.rows(agent, True)[-1].id)

    def said(self, fragment: str, timeout: float = 30.0) -> str:
        return str(
            wait_until(
                lambda: next((m for m in self.widget.messages.messages() if fragment in m), None),
                timeout,
                f"a message with {fragment!r}",
            )
        )

    def context_menu_choose(self, agent: str, blueprint: bool, row: int, text: str) -> None:
        """Right-click a row and choose ``text`` in the menu that opens."""
        table = self.table(agent, blueprint)
        chosen: list[str] = []

        def choose() -> None:
            menu = QApplication.activePopupWidget()
            if menu is None:
                QTimer.singleShot(20, choose)
                return
            texts = [a.text() for a in menu.actions()]
            action = next(a for a in menu.actions() if a.text() == text)
            chosen.extend(texts)
            menu.setActiveAction(action)
            QTest.keyClick(menu, Qt.Key_Return)

        QTimer.singleShot(20, choose)
        pos = table.visualRect(table.section.index(row, SKILL)).center()
        event = QContextMenuEvent(QContextMenuEvent.Mouse, pos, table.viewport().mapToGlobal(pos))
        QApplication.sendEvent(table.viewport(), event)
        assert text in chosen, chosen

    def answer_dialog(self, button: Any) -> None:
        """Press ``button`` in the next modal dialog (as soon as it opens)."""

        tries = [1500]  # 30 s: a dialog that never opens leaves no timer for later tests

        def press() -> None:
            box = QApplication.activeModalWidget()
            if isinstance(box, QMessageBox) and box.button(button) is not None:
                box.button(button).click()
            elif tries[0] > 0:
                tries[0] -= 1
                QTimer.singleShot(20, press)

        QTimer.singleShot(20, press)


def row_colour(gui: Gui, agent: str, blueprint: bool, row: int) -> str:
    return str(gui.cell(agent, blueprint, row, STATUS, Qt.BackgroundRole).color().name())


@pytest.fixture
def team(ros_master: Any, tmp_path: Path) -> Iterator[tuple[RosmcSystem, Operator, Gui]]:
    """Server, two executors, and the command widget following them."""
    library = tmp_path / "command_team.yaml"
    library.write_text(LIBRARY)
    system = RosmcSystem(ros_master.env, tmp_path / "system", library)
    system.start_server()
    for agent in AGENTS:
        system.start_executor(agent)
    operator = Operator()
    operator.wait_links(AGENTS)
    app = QApplication.instance() or QApplication([])
    widget, bridge = build(timeout=30.0)
    widget.resize(1500, 900)
    widget.show()
    widget.activateWindow()  # shortcuts need an active window
    QTest.qWaitForWindowActive(widget, 2000)
    gui = Gui(widget, bridge)
    wait_until(lambda: widget.view.loaded and widget.view.library, 60, "the mission is shown")
    try:
        yield system, operator, gui
    finally:
        bridge.close()
        widget.close()
        widget.deleteLater()
        app.processEvents()
        operator.close()
        system.close()


def test_operator_builds_edits_runs_and_adapts_a_two_robot_mission(team: Any) -> None:
    _system, operator, gui = team
    w = gui.widget
    # -- build: skills from each robot's Add menu ------------------------------------------
    probe = gui.add("r1", "probe")
    first = gui.add("r1", "wait")
    partner = gui.add("r2", "wait")
    long_wait = gui.add("r2", "wait")
    mission = operator.mission()
    assert [s.skill for s in mission.task("r1")] == ["probe", "wait"]
    assert [s.skill for s in mission.task("r2")] == ["wait", "wait"]
    assert w.tasks.selected_ids == [long_wait]  # a new skill is selected for editing

    # -- edit every parameter type of the probe ---------------------------------------------
    gui.click_row("r1", True, 0)
    wait_until(lambda: w.parameters.skill and w.parameters.skill.id == probe, 30, "probe shown")
    editors = w.parameters.editors
    spin = editors["duration"].spin
    spin.lineEdit().selectAll()
    QTest.keyClicks(spin.lineEdit(), "0.3")
    QTest.keyClick(spin.lineEdit(), Qt.Key_Return)
    gui.said("change duration")
    QTest.mouseClick(editors["fail"].box, Qt.LeftButton)
    gui.said("change fail")
    repeats = editors["repeats"].spin
    repeats.lineEdit().selectAll()
    QTest.keyClicks(repeats.lineEdit(), "4")
    QTest.keyClick(repeats.lineEdit(), Qt.Key_Return)
    QTest.keyClick(editors["mode"].combo, Qt.Key_Down)  # quick -> standard
    for name, text in (("note", "basalt?"), ("tags", '["a", "b"]'), ("extra", '{"k": 2}')):
        line = editors[name].line
        line.selectAll()
        QTest.keyClicks(line, text)
        QTest.keyClick(line, Qt.Key_Return)
    pose = editors["target"].spins
    for axis, text in (("x", "3.5"), ("yaw", "90")):
        pose[axis].lineEdit().selectAll()
        QTest.keyClicks(pose[axis].lineEdit(), text)
        QTest.keyClick(pose[axis].lineEdit(), Qt.Key_Return)
    area = editors["area"]
    QTest.mouseClick(area.add_button, Qt.LeftButton)  # a fourth corner
    wait_until(
        lambda: (
            len(operator.mission().skill(probe).params["area"]) == 4
            and operator.mission().skill(probe).params["target"].yaw != 0
        ),
        30,
        "every edit on the server",
    )
    params = operator.mission().skill(probe).params
    assert params["duration"] == pytest.approx(0.3)
    assert params["fail"] is True
    assert params["repeats"] == 4
    assert params["mode"] == "standard"
    assert params["note"] == "basalt?"
    assert params["tags"] == ["a", "b"] and params["extra"] == {"k": 2}
    assert params["target"].x == pytest.approx(3.5)
    assert params["target"].yaw == pytest.approx(math.pi / 2)
    # An invalid list is refused before it is sent, with a sentence.
    tags = editors["tags"].line
    tags.selectAll()
    QTest.keyClicks(tags, "[unclosed")
    QTest.keyClick(tags, Qt.Key_Return)
    gui.said("Not sent")
    assert operator.mission().skill(probe).params["tags"] == ["a", "b"]

    # -- a task marker: bind by choosing it, rename by typing --------------------------------
    client = MissionClient(5.0)
    client.add_task_marker(TaskMarker("rock", MarkerType.POSE, Pose(7.0, 8.0)))
    picker = wait_until(
        lambda: (
            w.parameters.pickers["target"].index_of("rock") == 1 and w.parameters.pickers["target"]
        ),
        30,
        "the marker offered",
    )
    QTest.keyClick(picker, Qt.Key_Down)  # Typed coordinates -> rock, the first place
    picker = wait_until(lambda: w.parameters.pickers["target"], 30, "picker rebuilt")
    wait_until(lambda: w.parameters.skill.bindings.get("target") == "rock", 30, "the binding shown")
    picker.lineEdit().selectAll()
    QTest.keyClicks(picker.lineEdit(), "big_rock")
    QTest.keyClick(picker.lineEdit(), Qt.Key_Return)
    wait_until(
        lambda: operator.mission().skill(probe).bindings.get("target") == "big_rock", 30, "rename"
    )
    client.close()

    # -- reorder: Move down button, then a drop -----------------------------------------------
    gui.click_row("r1", True, 0)
    gui.click("button_move_down")
    wait_until(lambda: [s.id for s in gui.rows("r1", True)] == [first, probe], 30, "moved")
    assert [s.id for s in operator.mission().task("r1")] == [first, probe]
    assert w.tasks.selected_ids == [probe]  # the selection followed the row
    model = gui.table("r1", True).section
    model.dropMimeData(model.mimeData([model.index(1, 0)]), Qt.MoveAction, 0, 0, QModelIndex())
    wait_until(lambda: [s.id for s in gui.rows("r1", True)] == [probe, first], 30, "dropped")
    model.dropMimeData(model.mimeData([model.index(0, 0)]), Qt.MoveAction, 2, 0, QModelIndex())
    wait_until(lambda: [s.id for s in gui.rows("r1", True)] == [first, probe], 30, "dropped back")

    # -- a barrier across robots with Ctrl-click ------------------------------------------------
    gui.click_row("r1", True, 0)
    gui.click_row("r2", True, 0, Qt.ControlModifier)
    assert w.tasks.selected_ids == [first, partner]
    gui.click("button_barrier")
    wait_until(lambda: operator.mission().barrier_of(first) is not None, 30, "barrier")
    assert set(operator.mission().barrier_of(first).skill_ids) == {first, partner}
    wait_until(lambda: gui.cell("r1", True, 0, TAG, Qt.DisplayRole) == "B1", 30, "tag shown")
    tag_r1 = gui.cell("r1", True, 0, TAG, Qt.BackgroundRole).color().name()
    assert gui.cell("r2", True, 0, TAG, Qt.DisplayRole) == "B1"
    assert gui.cell("r2", True, 0, TAG, Qt.BackgroundRole).color().name() == tag_r1

    # -- synchronize r1 up to the barrier member: the GUI warns first ----------------------------
    gui.click_row("r1", True, 0)
    gui.answer_dialog(QMessageBox.Yes)
    gui.click("button_synchronize")
    gui.said("wait at a barrier for ever")
    wait_until(lambda: gui.rows("r1", False) and gui.rows("r1", False)[0].id == first, 30, "synced")
    assert operator.mission().skill(first).status is S.IDLE_SYNCHRONIZED
    assert w.tasks.selected_ids == [first]  # followed into the synchronized table
    # Send r2's wait (with its long duration first set) with the column's Send to robot
    # button, answering its question with Send.
    gui.click_row("r2", True, 1)
    wait_until(lambda: w.parameters.skill and w.parameters.skill.id == long_wait, 30, "shown")
    spin = w.parameters.editors["duration"].spin
    spin.lineEdit().selectAll()
    QTest.keyClicks(spin.lineEdit(), "30")
    QTest.keyClick(spin.lineEdit(), Qt.Key_Return)
    wait_until(lambda: operator.mission().skill(long_wait).params["duration"] == 30.0, 30, "30 s")
    gui.answer_dialog(QMessageBox.Yes)
    gui.click("synchronize_all_r2")
    wait_until(lambda: len(gui.rows("r2", False)) == 2, 30, "r2 synced")

    # -- start: statuses and colours change live ----------------------------------------------
    gui.click("button_start_all")
    operator.wait_status([first, partner], S.SUCCESS, 20)
    wait_until(
        lambda: row_colour(gui, "r1", False, 0) == presentation.STATUS_COLOURS[S.SUCCESS],
        30,
        "r1's wait shown done",
    )
    operator.wait_status([long_wait], S.RUNNING, 10)
    wait_until(
        lambda: row_colour(gui, "r2", False, 1) == presentation.STATUS_COLOURS[S.RUNNING],
        30,
        "r2's long wait shown running",
    )
    assert gui.cell("r2", False, 1, STATUS, Qt.DisplayRole).startswith("running")

    # -- pause / resume / stop r2 from its column ---------------------------------------------
    gui.click("pause_r2")
    operator.wait_status([long_wait], S.PAUSED, 10)
    wait_until(
        lambda: row_colour(gui, "r2", False, 1) == presentation.STATUS_COLOURS[S.PAUSED],
        30,
        "paused",
    )
    wait_until(lambda: gui.column("r2").buttons[_robot("RESUME")].isEnabled(), 30, "resume enabled")
    gui.click("resume_r2")
    operator.wait_status([long_wait], S.RUNNING, 10)
    wait_until(lambda: gui.column("r2").buttons[_robot("STOP")].isEnabled(), 30, "stop enabled")
    gui.click("stop_r2")
    operator.wait_status([long_wait], S.IDLE_SYNCHRONIZED, 10)

    # -- unsynchronize mid-run, edit, resynchronize: a failure, retry, skip -----------------
    wait_until(lambda: gui.rows("r2", False)[1].status is S.IDLE_SYNCHRONIZED, 30, "stopped")
    gui.click_row("r2", False, 1)
    gui.click("button_unsynchronize")
    wait_until(lambda: [s.id for s in gui.rows("r2", True)] == [long_wait], 30, "taken back")
    assert operator.mission().skill(long_wait).status is S.IDLE
    gui.click_row("r1", True, 0)  # r1's probe (fail is set): send it and run it
    gui.click("button_synchronize")
    wait_until(lambda: len(gui.rows("r1", False)) == 2, 30, "probe on r1")
    # r1 is still started (Start all): it runs what arrives.
    operator.wait_status([probe], S.FAILURE, 20)
    wait_until(
        lambda: row_colour(gui, "r1", False, 1) == presentation.STATUS_COLOURS[S.FAILURE], 30, "red"
    )
    gui.click_row("r1", False, 1)
    wait_until(lambda: w.actions_.skill[_action("RETRY")].isEnabled(), 30, "retry enabled")
    gui.context_menu_choose("r1", False, 1, "Retry")
    retried = wait_until(
        lambda: len(operator.mission().task("r1")) == 3 and operator.mission().task("r1")[2],
        30,
        "retry",
    )
    assert retried.skill == "probe" and retried.attempt == 2
    operator.wait_status([retried.id], S.FAILURE, 20)
    wait_until(lambda: len(gui.rows("r1", False)) == 3, 30, "retry shown")
    gui.click_row("r1", False, 2)
    wait_until(lambda: w.actions_.skill[_action("SKIP")].isEnabled(), 30, "skip enabled")
    gui.click("button_skip")
    wait_until(
        lambda: operator.mission().skill(retried.id).resolution.name == "SKIPPED", 30, "skipped"
    )
    wait_until(
        lambda: row_colour(gui, "r1", False, 2) == presentation.SETTLED_FAILURE_COLOUR, 30, "faded"
    )
    refusals = [m for m in w.messages.messages() if "Could not" in m]
    assert not refusals, refusals


def test_a_policy_set_with_the_cli_opens_the_link_loss_dialog_on_it(
    team: Any, tmp_path: Path
) -> None:
    system, _operator, gui = team
    rosmc = [sys.executable, str(REPO_ROOT / "scripts" / "rosmc"), "lost-link-policy", "r2"]
    chosen = ["safe_skill", "--skill", "wait", "--param", "duration=5", "--after", "45"]
    done = subprocess.run(
        [*rosmc, *chosen, "--when", "idle"],
        env=dict(system.env),
        capture_output=True,
        text=True,
        timeout=60.0,
        check=False,
    )
    assert done.returncode == 0, done.stderr
    reported = LostLinkPolicy(
        LostLinkKind.SAFE_SKILL, 45.0, "wait", {"duration": 5.0}, LostLinkTrigger.IDLE
    )
    column = gui.column("r2")
    wait_until(
        lambda: column.policy_in_force is not None and column.policy_in_force.policy == reported,
        60,
        "r2 reporting the policy in force",
    )
    seen: list[tuple[LostLinkPolicy, str]] = []

    def look() -> None:
        dialog = QApplication.activeModalWidget()
        if not isinstance(dialog, PolicyDialog) or not dialog.isVisible():
            QTimer.singleShot(20, look)
            return
        seen.append((dialog.policy(), dialog.in_force.text()))
        dialog.grab().save(str(tmp_path / "policy_dialog.png"))
        QTest.mouseClick(dialog.buttons.button(dialog.buttons.Cancel), Qt.LeftButton)

    QTimer.singleShot(20, look)
    QTest.mouseClick(column.policy_button, Qt.LeftButton)
    preselected = LostLinkPolicy(LostLinkKind.SAFE_SKILL, 45.0, "wait", when=LostLinkTrigger.IDLE)
    in_force = "In force: on link loss: run wait after 45 s idle without a link, then hold"
    assert seen == [(preselected, in_force)], "the dialog opened on the policy the CLI set"


def _action(name: str) -> Any:
    from rosmc_rqt_command.core.legality import Action

    return Action[name]


def _robot(name: str) -> Any:
    from rosmc_rqt_command.core.legality import RobotAction

    return RobotAction[name]
