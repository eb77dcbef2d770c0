"""The command GUI (real widget, offscreen) warns in the robot's column when its task ends
out of coverage, and its policy dialog shows the policy in force and offers the return."""

from __future__ import annotations

from collections.abc import Iterator, Sequence

import pytest
from python_qt_binding.QtCore import Qt
from python_qt_binding.QtTest import QTest

from rosmc_rqt_command.qt.policy_dialog import PolicyDialog
from rosmc_server.core import (
    AgentStatus,
    Library,
    LostLinkKind,
    LostLinkPolicy,
    LostLinkTrigger,
    Mission,
    PolicyInForce,
)
from tests.unit.test_command_harness import Gui, open_gui

WARNING = (
    "the task ends out of coverage at (17.0, 0.0) (predicted -71 dBm) and the lost-link "
    "policy would leave the robot there"
)
DEFAULT = PolicyInForce(
    LostLinkPolicy(LostLinkKind.RETURN_TO_LINK, 60.0, "move", when=LostLinkTrigger.IDLE),
    library_default=True,
)


@pytest.fixture
def gui(mission: Mission, library: Library) -> Iterator[Gui]:
    yield from open_gui(mission, library)


def test_the_column_warns_while_the_server_does(gui: Gui) -> None:
    column = gui.widget.tasks.columns["alpha"]
    assert not column.warning_label.isVisibleTo(gui.widget)
    gui.feed.statuses(AgentStatus("alpha", link="up", lost_link=PolicyInForce(),
                                  coverage_warning=WARNING))  # fmt: skip
    gui.widget.repaints.show_statuses_now()  # the header refreshes on its timer
    assert column.warning_label.isVisibleTo(gui.widget)
    assert column.warning_label.text() == "⚠ T" + WARNING[1:]
    assert "Link loss" in column.warning_label.toolTip()
    other = gui.widget.tasks.columns["bravo"]
    assert not other.warning_label.isVisibleTo(gui.widget)
    gui.feed.statuses(AgentStatus("alpha", link="up", lost_link=DEFAULT))  # the operator fixed it
    gui.widget.repaints.show_statuses_now()
    assert not column.warning_label.isVisibleTo(gui.widget)


def test_the_dialog_shows_the_policy_in_force_and_offers_the_return(gui: Gui) -> None:
    column = gui.widget.tasks.columns["alpha"]
    gui.feed.statuses(AgentStatus("alpha", link="up", lost_link=DEFAULT))
    gui.widget.repaints.show_statuses_now()
    shown: list[str] = []

    def ask(
        agent: str,
        skills: Sequence[str],
        parent: object,
        in_force: PolicyInForce | None,
        *_: object,
    ) -> LostLinkPolicy:
        dialog = PolicyDialog(agent, skills, parent=None, in_force=in_force)
        shown.append(dialog.in_force.text())
        dialog.set_kind(LostLinkKind.RETURN_TO_LINK)
        assert dialog.idle_check.isChecked() and dialog.skill_combo.isEnabled()
        dialog.after_spin.setValue(90)
        return dialog.policy()

    column.ask_policy = ask
    QTest.mouseClick(column.policy_button, Qt.LeftButton)
    assert shown == [f"In force: {DEFAULT.describe()}"]
    [request] = gui.backend.requests
    assert request.args == (
        "alpha",
        LostLinkPolicy(LostLinkKind.RETURN_TO_LINK, 90.0, "move", when=LostLinkTrigger.IDLE),
    )
