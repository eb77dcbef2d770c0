"""The task panel: rows change only where an update touched them; the selection survives.

Each model's change signals are recorded while a real mission changes one thing at a
time; only the rows of that change may be reported, in the column of that robot.
"""

from __future__ import annotations

import time
from collections.abc import Iterator
from typing import Any

import pytest
from python_qt_binding.QtCore import Qt
from python_qt_binding.QtTest import QTest

from rosmc_rqt_command.qt.task_model import STATUS, TaskModel
from rosmc_server.core import AgentStatus, Library, Mission, SkillStatus
from tests.unit.test_command_harness import Gui, open_gui

S = SkillStatus


@pytest.fixture
def gui(mission: Mission, library: Library) -> Iterator[Gui]:
    """A command widget following the ``mission`` fixture."""
    yield from open_gui(mission, library)


class Signals:
    """Every row change each model of the task panel reports."""

    def __init__(self, gui: Gui) -> None:
        self.seen: list[tuple[str, str, int, int]] = []
        for agent, column in gui.widget.tasks.columns.items():
            for name, model in (
                ("synced", column.synced_model),
                ("blueprint", column.blueprint_model),
            ):
                self._watch(f"{agent}/{name}", model)

    def _watch(self, key: str, model: TaskModel) -> None:
        def record(kind: str) -> Any:
            def slot(first: Any, last: Any, *_rest: Any) -> None:
                if kind == "changed":
                    self.seen.append((key, kind, first.row(), last.row()))
                else:
                    self.seen.append((key, kind, first, last))

            return slot

        model.dataChanged.connect(record("changed"))
        model.rowsInserted.connect(lambda _p, a, b: self.seen.append((key, "inserted", a, b)))
        model.rowsRemoved.connect(lambda _p, a, b: self.seen.append((key, "removed", a, b)))
        model.modelReset.connect(lambda: self.seen.append((key, "reset", -1, -1)))

    def take(self) -> list[tuple[str, str, int, int]]:
        seen, self.seen = self.seen, []
        return seen


def test_each_change_touches_only_its_rows(gui: Gui) -> None:
    feed = gui.feed
    alpha = [feed.add("alpha", "move") for _ in range(4)]
    bravo = [feed.add("bravo", "wait") for _ in range(3)]
    signals = Signals(gui)

    feed("edit_skill", alpha[2], label="sample the crater rim")
    assert signals.take() == [("alpha/blueprint", "changed", 2, 2)]
    assert gui.cell("alpha", True, 2, 2, Qt.DisplayRole) == "sample the crater rim"

    new = feed.add("bravo", "scan")
    assert signals.take() == [("bravo/blueprint", "inserted", 3, 3)]

    feed("delete_skills", [bravo[0]])
    # The row goes; the rows below keep their data (their number is their position).
    assert signals.take() == [("bravo/blueprint", "removed", 0, 0)]
    assert gui.cell("bravo", True, 0, 1, Qt.DisplayRole) == "1"
    assert gui.ids("bravo", True) == [bravo[1], bravo[2], new]

    feed("reorder", "alpha", [alpha[1], alpha[0], alpha[2], alpha[3]])
    changes = signals.take()
    assert {key for key, *_ in changes} == {"alpha/blueprint"}
    rows = {row for _key, _kind, first, last in changes for row in range(first, last + 1)}
    assert rows == {0, 1}, changes  # rows 2 and 3 kept their skill

    feed.sync("alpha", alpha[0])  # the first two go to the robot
    assert signals.take() == [
        # uploading: the two rows turn pending
        ("alpha/blueprint", "changed", 0, 0),
        ("alpha/blueprint", "changed", 1, 1),
        # confirmed: they move to the robot's table; the rest are numbered on from there
        ("alpha/synced", "inserted", 0, 1),
        ("alpha/blueprint", "removed", 0, 1),
        ("alpha/blueprint", "changed", 0, 0),
        ("alpha/blueprint", "changed", 1, 1),
    ]
    assert gui.cell("alpha", True, 0, 1, Qt.DisplayRole) == "3"
    assert gui.ids("alpha", False) == [alpha[1], alpha[0]]
    assert gui.ids("alpha", True) == [alpha[2], alpha[3]]

    feed("report_status", alpha[1], S.RUNNING)
    assert signals.take() == [("alpha/synced", "changed", 0, 0)]
    assert "reset" not in {kind for _key, kind, *_ in signals.take()}


def test_robot_reports_repaint_headers_not_rows(gui: Gui) -> None:
    gui.feed.add("alpha", "move")
    signals = Signals(gui)
    gui.feed.statuses(AgentStatus("alpha", link="up", last_heard=0.2, battery=0.8))
    assert signals.take() == []
    label = gui.widget.tasks.columns["alpha"].status_label
    _wait(lambda: "battery 80%" in label.text())


def test_a_barrier_partner_repaints_only_its_own_row(gui: Gui) -> None:
    feed = gui.feed
    first = feed.add("alpha", "wait")
    other = feed.add("alpha", "wait")
    partner = feed.add("bravo", "wait")
    feed("add_barrier", [first, partner])
    feed.sync("alpha")
    feed.sync("bravo")
    signals = Signals(gui)
    feed("edit_skill", feed.add("charlie", "wait"), label="elsewhere")
    assert {key for key, *_ in signals.take()} == {"charlie/blueprint"}
    feed("report_status", first, S.SYNCWAITING)  # alpha waits for bravo
    assert sorted(signals.take()) == [
        ("alpha/synced", "changed", 0, 0),
        ("bravo/synced", "changed", 0, 0),
    ]
    assert gui.cell("alpha", False, 0, STATUS, Qt.DisplayRole) == "waiting on bravo"
    assert gui.ids("alpha", False) == [first, other]


def test_selection_follows_skills_across_updates(gui: Gui) -> None:
    feed = gui.feed
    ids = [feed.add("alpha", "move") for _ in range(3)]
    gui.click_row("alpha", True, 1)
    assert gui.widget.tasks.selected_ids == [ids[1]]
    feed("reorder", "alpha", [ids[1], ids[0], ids[2]])  # the selected skill moves up
    assert gui.widget.tasks.selected_ids == [ids[1]]
    assert _selected_rows(gui, "alpha", True) == [0]
    feed.add("alpha", "scan")  # another row arrives
    feed("edit_skill", ids[1], label="renamed")  # the selected skill itself changes
    assert _selected_rows(gui, "alpha", True) == [0]
    feed.sync("alpha", ids[1])  # it moves to the robot's table
    assert gui.widget.tasks.selected_ids == [ids[1]]
    assert _selected_rows(gui, "alpha", False) == [0]
    assert _selected_rows(gui, "alpha", True) == []
    assert gui.widget.parameters.skill is not None
    assert gui.widget.parameters.skill.id == ids[1]
    assert gui.widget.parameters.skill.label == "renamed"
    feed("delete_skills", [ids[0]])  # another robot's change leaves it alone
    assert gui.widget.tasks.selected_ids == [ids[1]]


def test_several_selected_show_no_skills_label_or_options(gui: Gui) -> None:
    feed = gui.feed
    first, second = feed.add("alpha", "move"), feed.add("alpha", "move")
    feed("edit_skill", first, label="sample the crater rim", timeout=30.0, max_retries=2)
    panel = gui.widget.parameters
    gui.click_row("alpha", True, 0)
    assert panel.label_edit.text() == "sample the crater rim"
    assert (panel.timeout_spin.text(), panel.retries_spin.text()) == ("30.00 s", "2")
    gui.click_row("alpha", True, 1, Qt.ControlModifier)
    assert gui.widget.tasks.selected_ids == [first, second]
    assert panel.label_edit.text() == "", "the first skill's label passes for the selection's"
    assert (panel.timeout_spin.text(), panel.retries_spin.text()) == (" ", " ")
    gui.click_row("alpha", True, 1)  # the other one alone: its own values, zeros shown
    assert panel.label_edit.text() == "move"
    assert (panel.timeout_spin.text(), panel.retries_spin.text()) == ("0.00 s", "0")


def test_ctrl_click_selects_across_columns_and_a_plain_click_lets_go(gui: Gui) -> None:
    feed = gui.feed
    a = [feed.add("alpha", "move") for _ in range(2)]
    b = feed.add("bravo", "move")
    c = feed.add("charlie", "move")
    gui.click_row("alpha", True, 0)
    gui.click_row("alpha", True, 1, Qt.ControlModifier)
    gui.click_row("bravo", True, 0, Qt.ControlModifier)
    gui.click_row("charlie", True, 0, Qt.ControlModifier)
    assert gui.widget.tasks.selected_ids == [a[0], a[1], b, c]
    assert gui.widget.parameters.title.text() == "<i>4 skills selected.</i>"
    feed("edit_skill", b, label="kept")  # a live update keeps the whole selection
    assert gui.widget.tasks.selected_ids == [a[0], a[1], b, c]
    gui.click_row("bravo", True, 0)
    assert gui.widget.tasks.selected_ids == [b]
    assert _selected_rows(gui, "alpha", True) == []
    # The selection goes to rviz with the markers it uses.
    assert gui.backend.selections[-1] == ([b], [])


def test_a_selected_skill_that_is_deleted_leaves_the_selection(gui: Gui) -> None:
    skill = gui.feed.add("alpha", "move")
    gui.click_row("alpha", True, 0)
    gui.feed("delete_skills", [skill])
    assert gui.widget.tasks.selected_ids in ([], [skill])
    assert gui.ids("alpha", True) == []
    assert gui.widget.parameters.skill is None


def _selected_rows(gui: Gui, agent: str, blueprint: bool) -> list[int]:
    table = gui.table(agent, blueprint)
    return sorted(index.row() for index in table.selectionModel().selectedRows())


def _wait(condition: Any, timeout: float = 30.0) -> None:
    deadline = time.monotonic() + timeout
    while not condition():
        assert time.monotonic() < deadline, "timed out"
        QTest.qWait(10)
