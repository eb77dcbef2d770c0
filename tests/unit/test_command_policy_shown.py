"""The *Link loss…* dialog opens on the policy in force, and a policy waiting is shown.

The robot reports its policy typed (:attr:`AgentStatus.lost_link`); nothing reads words back.

The real column and the real dialog (offscreen Qt): the operator clicks *Link loss…*, the
test reads the open dialog and presses its buttons with the mouse.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from typing import Any

import pytest
from python_qt_binding.QtCore import Qt, QTimer
from python_qt_binding.QtTest import QTest
from python_qt_binding.QtWidgets import QApplication

from rosmc_rqt_command.qt.policy_dialog import PolicyDialog
from rosmc_server.core import (
    AgentStatus,
    Library,
    LostLinkKind,
    LostLinkPolicy,
    Mission,
    PolicyInForce,
)
from rosmc_server.core import LostLinkTrigger as T
from rosmc_server.core.skills.library import library_from_dict
from tests.team_gui import settle
from tests.unit.conftest import make_mission
from tests.unit.test_command_harness import Gui, open_gui

HOLD_30 = LostLinkPolicy(LostLinkKind.HOLD, 30.0)


@pytest.fixture
def gui(mission: Mission, library: Library) -> Iterator[Gui]:
    """A command widget following the ``mission`` fixture."""
    yield from open_gui(mission, library)


@pytest.mark.parametrize(
    "policy",
    [
        LostLinkPolicy(),
        HOLD_30,
        LostLinkPolicy(LostLinkKind.HOLD, 12.0, when=T.IDLE),
        LostLinkPolicy(LostLinkKind.SAFE_SKILL, 60.0, "wait"),
        LostLinkPolicy(LostLinkKind.RETURN_TO_LINK, 90.0, "move", when=T.IDLE),
    ],
)
def test_the_dialog_opens_on_each_kind_in_force(policy: LostLinkPolicy) -> None:
    app = QApplication.instance() or QApplication([])  # kept alive for the whole test
    in_force = PolicyInForce(policy, library_default=True, acted="held after 68 s")
    dialog = PolicyDialog("alpha", ["move", "wait"], preferred="wait", in_force=in_force)
    assert dialog.policy() == policy
    assert dialog.in_force.text() == f"In force: {in_force.describe()}"
    dialog.close()
    assert app is not None


def with_dialog(handle: Callable[[PolicyDialog], None], press: Callable[[], None]) -> None:
    """Press something that opens the policy dialog, and handle the dialog once."""
    handled: list[bool] = []

    def poll() -> None:
        dialog = QApplication.activeModalWidget()
        if isinstance(dialog, PolicyDialog) and dialog.isVisible() and not handled:
            handled.append(True)
            handle(dialog)
        elif not handled:
            QTimer.singleShot(20, poll)

    QTimer.singleShot(20, poll)
    press()
    assert handled, "the dialog opened"


def test_the_dialog_opens_on_the_policy_in_force_and_shows_one_waiting(gui: Gui) -> None:
    column = gui.widget.tasks.columns["alpha"]
    reported = LostLinkPolicy(LostLinkKind.SAFE_SKILL, 45.0, "wait", when=T.IDLE)
    gui.feed.statuses(
        AgentStatus("alpha", link="down", last_heard=20.0, lost_link=PolicyInForce(reported))
    )
    settle(gui.widget)
    seen: list[LostLinkPolicy] = []

    def choose_hold(dialog: PolicyDialog) -> None:
        seen.append(dialog.policy())
        assert not dialog.pending.isVisible()
        dialog.set_kind(LostLinkKind.HOLD)
        dialog.after_spin.setValue(30)
        dialog.idle_check.setChecked(False)
        QTest.mouseClick(dialog.buttons.button(dialog.buttons.Ok), Qt.LeftButton)

    click = lambda: QTest.mouseClick(column.policy_button, Qt.LeftButton)  # noqa: E731
    with_dialog(choose_hold, click)
    assert seen == [reported], "it opened on the policy in force, not on keep going"
    assert gui.backend.requests[-1].args == ("alpha", HOLD_30)
    gui.feed.statuses(
        AgentStatus("alpha", link="down", last_heard=21.0, lost_link=PolicyInForce(reported))
    )
    settle(gui.widget)
    assert "new policy waiting for contact: on link loss: hold after 30 s" in (
        column.status_label.text()
    )

    def look(dialog: PolicyDialog) -> None:
        seen.append(dialog.policy())
        assert dialog.pending.isVisibleTo(dialog)
        assert "Waiting for contact: on link loss: hold after 30 s" in dialog.pending.text()
        QTest.mouseClick(dialog.buttons.button(dialog.buttons.Cancel), Qt.LeftButton)

    with_dialog(look, click)
    assert seen[-1] == HOLD_30, "it opened on the policy waiting"
    # The robot reports it with what it did: still the policy taken.
    took = PolicyInForce(HOLD_30, acted="held after 31 s without ground contact")
    gui.feed.statuses(AgentStatus("alpha", link="up", last_heard=0.0, lost_link=took))
    settle(gui.widget)
    assert "waiting for contact" not in column.status_label.text()


def test_before_the_robot_reports_the_dialog_opens_on_the_librarys_default(
    library_data: dict[str, Any],
) -> None:
    library_data["models"]["walker"]["lost_link"] = {"policy": "hold", "after": 20}
    library = library_from_dict(library_data, "unit_team.yaml")
    gui = Gui(make_mission(library), library)
    try:
        settle(gui.widget)
        column = gui.widget.tasks.columns["alpha"]
        seen: list[tuple[LostLinkPolicy, str]] = []

        def look(dialog: PolicyDialog) -> None:
            seen.append((dialog.policy(), dialog.in_force.text()))
            QTest.mouseClick(dialog.buttons.button(dialog.buttons.Cancel), Qt.LeftButton)

        with_dialog(look, lambda: QTest.mouseClick(column.policy_button, Qt.LeftButton))
        default = LostLinkPolicy(LostLinkKind.HOLD, 20.0)
        assert seen == [
            (default, f"In force: {default.describe()} (library default, not reported yet)")
        ], "not on keep going"
    finally:
        gui.close()
