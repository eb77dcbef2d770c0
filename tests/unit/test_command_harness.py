"""The command GUI's unit-test harness (offscreen Qt, no ROS), and checks of the harness.

A real :class:`~rosmc_server.core.Mission` makes the changes; its events go through a
real :class:`~rosmc_server.core.live.mirror.MissionMirror` and
:func:`~rosmc_rqt_command.core.view_state.view_update` (the code the ROS bridge runs) into the
widget, so the widget sees exactly the updates it would see live. Only the ROS side is
absent: requests the widget sends are recorded by :class:`RecordingBackend` (tests may
apply them to the mission, as the server would).

Other ``test_command_*`` modules import the helpers (``tests.unit.test_command_harness``).
"""

from __future__ import annotations

import os
from collections.abc import Callable, Iterator
from typing import Any

import pytest

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")

from python_qt_binding.QtCore import Qt
from python_qt_binding.QtTest import QTest
from python_qt_binding.QtWidgets import QApplication

from rosmc_rqt_command.core.legality import Action
from rosmc_rqt_command.core.requests import Request
from rosmc_rqt_command.core.view_state import ViewUpdate, view_update
from rosmc_rqt_command.qt.command_widget import CommandWidget
from rosmc_rqt_command.qt.section_table import SectionTable
from rosmc_rqt_command.qt.task_model import SKILL, STATUS
from rosmc_server.core import AgentStatus, Library, Mission, MissionEvent, MissionState
from rosmc_server.core.live.mirror import MissionMirror
from rosmc_server.core.live.updates import MirrorUpdate


def qt_app() -> QApplication:
    """The process's QApplication (offscreen)."""
    app = QApplication.instance()
    return app if app is not None else QApplication([])


class RecordingBackend:
    """The widget's :class:`~rosmc_rqt_command.core.requests.Backend`, recording requests."""

    def __init__(self, read_only: bool = False) -> None:
        self.read_only = read_only
        self.requests: list[Request] = []
        self.refreshes = 0
        self.selections: list[tuple[list[str], list[str]]] = []

    def request(self, request: Request) -> None:
        """Keep ``request`` (the test answers it if it wants to)."""
        self.requests.append(request)

    def refresh(self) -> None:
        """Count refreshes."""
        self.refreshes += 1

    def publish_selection(self, skill_ids: list[str], marker_names: list[str]) -> None:
        """Keep what would go to rviz."""
        self.selections.append((list(skill_ids), list(marker_names)))

    def operations(self) -> list[str]:
        """The operations requested so far, in order."""
        return [r.operation for r in self.requests]


class Feed:
    """A real mission whose every change reaches ``targets`` through a real mirror.

    ``feed("add_skill", "alpha", "move")`` runs the mission's method and hands its event
    to the mirror; each mirror update becomes a :class:`ViewUpdate` (as the bridge makes
    it) and goes to every target, in order.
    """

    def __init__(self, mission: Mission, *targets: Callable[[ViewUpdate], None]) -> None:
        self.mission = mission
        self.targets = list(targets)
        self.updates: list[ViewUpdate] = []
        self.mirror = MissionMirror()
        self.mirror.subscribe(self._on_mirror_update)
        self.mirror.on_snapshot(MissionState(mission.state.content(), mission.revision))

    def _on_mirror_update(self, update: MirrorUpdate) -> None:
        converted = view_update(update, self.mirror.state)
        self.updates.append(converted)
        for target in self.targets:
            target(converted)

    def __call__(self, operation: str, *args: Any, **kwargs: Any) -> MissionEvent:
        event: MissionEvent = getattr(self.mission, operation)(*args, **kwargs)
        self.mirror.on_event(event)
        return event

    def add(self, agent: str, skill: str = "move", **kwargs: Any) -> str:
        """Add a skill; its id."""
        event = self("add_skill", agent, skill, kwargs.pop("params", None), **kwargs)
        return str(event.change.put_skills[0].skill.id)

    def sync(self, agent: str, upto: str | None = None, confirm: bool = True) -> list[str]:
        """Synchronize (and let the robot confirm unless ``confirm`` is False); the ids."""
        event = self("synchronize", agent, upto)
        ids = [placed.skill.id for placed in event.change.put_skills]
        if confirm:
            self("confirm_synchronized", agent, ids)
        return ids

    def statuses(self, *statuses: AgentStatus) -> None:
        """Robots report (as ``/rosmc/agent_states`` would)."""
        self.mirror.on_agent_statuses({status.agent: status for status in statuses})


class Gui:
    """A command widget over a recording backend, fed by a real mission."""

    def __init__(self, mission: Mission, library: Library, read_only: bool = False) -> None:
        self.app = qt_app()
        self.backend = RecordingBackend(read_only)
        self.widget = CommandWidget(self.backend)
        self.widget.on_library(library)
        self.feed = Feed(mission, self.widget.on_update)
        self.widget.resize(1400, 800)
        self.widget.show()

    def close(self) -> None:
        """Close and delete the widget."""
        self.widget.close()
        self.widget.deleteLater()
        self.app.processEvents()

    def table(self, agent: str, blueprint: bool) -> SectionTable:
        """One robot's blueprint or synchronized table."""
        column = self.widget.tasks.columns[agent]
        return column.blueprint_table if blueprint else column.synced_table

    def ids(self, agent: str, blueprint: bool) -> list[str]:
        """The skill ids a table shows, top to bottom."""
        return [s.id for s in self.table(agent, blueprint).section.rows]

    def cell(self, agent: str, blueprint: bool, row: int, column: int, role: int) -> Any:
        """What a table's model answers for a cell."""
        model = self.table(agent, blueprint).section
        return model.data(model.index(row, column), role)

    def colour(self, agent: str, blueprint: bool, row: int) -> str:
        """The background colour of a row (#rrggbb)."""
        return str(self.cell(agent, blueprint, row, STATUS, Qt.BackgroundRole).color().name())

    def click_row(
        self, agent: str, blueprint: bool, row: int, modifier: Any = Qt.NoModifier
    ) -> None:
        """Click a row as the operator does (with Ctrl or Shift held if given)."""
        table = self.table(agent, blueprint)
        rect = table.visualRect(table.section.index(row, SKILL))
        QTest.mouseClick(table.viewport(), Qt.LeftButton, modifier, rect.center())

    def enabled(self) -> set[str]:
        """Object names of the enabled skill actions."""
        return {
            action.objectName().removeprefix("action_")
            for action in self.widget.actions_.skill.values()
            if action.isEnabled()
        }


def open_gui(mission: Mission, library: Library) -> Iterator[Gui]:
    """Body of each module's ``gui`` fixture: a widget following ``mission``, closed after."""
    harness = Gui(mission, library)
    yield harness
    harness.close()


@pytest.fixture
def gui(mission: Mission, library: Library) -> Iterator[Gui]:
    """A command widget following the ``mission`` fixture (unit-test library)."""
    yield from open_gui(mission, library)


# -- the harness itself ----------------------------------------------------------------------
def test_the_widget_shows_the_mission_the_mirror_follows(gui: Gui) -> None:
    first = gui.feed.add("alpha", "move")
    second = gui.feed.add("alpha", "scan")
    gui.feed.sync("alpha", first)
    assert gui.ids("alpha", False) == [first]
    assert gui.ids("alpha", True) == [second]
    assert gui.widget.view.revision == gui.feed.mission.revision
    assert set(gui.widget.tasks.columns) >= {"alpha", "bravo", "charlie"}


def test_requests_are_recorded_not_sent(gui: Gui) -> None:
    skill = gui.feed.add("bravo", "wait")
    gui.click_row("bravo", True, 0)
    gui.widget.do(Action.DELETE)
    assert gui.backend.operations() == ["delete_skills"]
    assert gui.backend.requests[0].args == ([skill],)
    assert gui.backend.requests[0].seen == gui.feed.mission.revision
