"""Warnings an operator needs in time: barriers that would wait for ever, robots leaving
Wi-Fi range with planned work, parameters the library refuses.
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import pytest

from rosmc_rqt_command.core import alerts
from rosmc_rqt_command.core.legality import Action
from rosmc_server.core import AgentStatus, Library, Mission, SkillStatus
from rosmc_server.core.skills.library import library_from_dict
from tests.unit.test_command_harness import Gui, open_gui

S = SkillStatus


@pytest.fixture
def gui(mission: Mission, library: Library) -> Iterator[Gui]:
    """A command widget following the ``mission`` fixture."""
    yield from open_gui(mission, library)


def test_sending_a_barrier_member_without_its_partner_asks_first(gui: Gui) -> None:
    feed = gui.feed
    first, partner = feed.add("alpha", "wait"), feed.add("bravo", "wait")
    feed("add_barrier", [first, partner])
    asked: list[list[str]] = []
    answers = [False, True]

    def confirm(warnings: list[str]) -> bool:
        asked.append(warnings)
        return answers.pop(0)

    gui.widget.dispatcher.confirm = confirm
    gui.click_row("alpha", True, 0)
    gui.widget.do(Action.SYNC)  # answered No: nothing is sent
    assert asked == [["alpha will wait at a barrier for ever unless you also send bravo's 'wait'."]]
    assert gui.backend.requests == []
    gui.widget.do(Action.SYNC)  # answered Yes
    assert gui.backend.operations() == ["synchronize"]
    assert gui.backend.requests[0].args == ("alpha", first)


def test_a_member_on_the_robot_with_its_partner_planned_is_a_standing_warning(gui: Gui) -> None:
    feed = gui.feed
    first, partner = feed.add("alpha", "wait"), feed.add("bravo", "wait")
    feed("add_barrier", [first, partner])
    assert alerts.barrier_warnings(gui.widget.view) == []
    feed.sync("alpha")
    _warn_now(gui)
    assert gui.widget.messages.warnings == [
        "alpha will wait at a barrier for ever unless you also send bravo's 'wait'."
    ]
    assert gui.widget.messages.warnings_label.isVisibleTo(gui.widget)
    feed.sync("bravo")
    _warn_now(gui)
    assert gui.widget.messages.warnings == []
    assert not gui.widget.messages.warnings_label.isVisibleTo(gui.widget)
    # Sending both together is fine: no question.
    assert alerts.barrier_warnings(gui.widget.view, gui.widget.view.skills([first, partner])) == []


@pytest.mark.parametrize(
    ("signal", "in_coverage", "planned", "expected"),
    [
        (-50.0, True, 2, None),
        (-80.0, True, 2, "alpha is about to leave Wi-Fi range (weak signal) with 2 planned skills"),
        (-80.0, True, 1, "alpha is about to leave Wi-Fi range (weak signal) with 1 planned skill "),
        (-95.0, False, 1, "alpha is out of Wi-Fi range with 1 planned skill not on board; what"),
        (-80.0, True, 0, None),  # nothing planned: nothing to lose
        (None, False, 2, None),  # no telemetry yet: no guess
    ],
)
def test_a_robot_leaving_coverage_with_planned_work(
    gui: Gui, signal: float | None, in_coverage: bool, planned: int, expected: str | None
) -> None:
    feed = gui.feed
    on_board = feed.add("alpha")
    feed.sync("alpha", on_board)  # work on board is not at risk
    for _ in range(planned):
        feed.add("alpha")
    feed.statuses(
        AgentStatus("alpha", link="up", wifi_signal=signal, in_coverage=in_coverage, battery=0.5)
    )
    warnings = alerts.coverage_warnings(gui.widget.view)
    gui.widget.repaints.show_statuses_now()
    _warn_now(gui)
    if expected is None:
        assert warnings == []
    else:
        assert len(warnings) == 1 and warnings[0].startswith(expected), warnings
        assert gui.widget.messages.warnings == warnings


def test_skills_sent_while_out_of_range_are_not_counted_again(gui: Gui) -> None:
    """Sent out of range, they wait for contact (the header says so): no alert about them."""
    feed = gui.feed
    waiting = feed.add("alpha")
    feed.add("alpha")
    out_of_range = AgentStatus(
        "alpha", link="down", wifi_signal=-95.0, in_coverage=False, battery=0.5
    )
    feed.statuses(out_of_range)
    feed.sync("alpha", waiting, confirm=False)  # held for contact: no answer from the robot
    assert alerts.coverage_warnings(gui.widget.view) == [
        "alpha is out of Wi-Fi range with 1 planned skill not on board; what you send now "
        "waits until it is heard again."
    ]
    feed.sync("alpha", confirm=False)
    assert alerts.coverage_warnings(gui.widget.view) == []


def test_forged_radio_datagrams_on_a_robots_link_are_a_warning_and_in_its_header(
    gui: Gui,
) -> None:
    from rosmc_rqt_command.core.presentation import link_summary
    from rosmc_rviz_markers.core.icons import link_row
    from rosmc_server.text import format_agent_status

    quiet = AgentStatus("alpha", link="up", last_heard=0.1)
    attacked = AgentStatus("alpha", link="up", last_heard=0.1, radio_dropped=212)
    gui.feed.statuses(quiet)
    assert alerts.radio_warnings(gui.widget.view) == []
    assert "forged" not in link_summary(quiet) and "forged" not in format_agent_status(quiet)
    gui.feed.statuses(attacked)
    gui.widget.repaints.show_statuses_now()
    _warn_now(gui)
    assert gui.widget.messages.warnings == [
        "alpha: 212 forged radio datagrams dropped (someone without the deployment's key is "
        "sending)."
    ]
    assert link_summary(attacked).endswith("212 forged radio datagrams dropped")
    assert "WARNING: 212 forged radio datagrams dropped" in format_agent_status(attacked)
    assert AgentStatus("alpha", radio_dropped=1).radio_text == "1 forged radio datagram dropped"
    row = link_row("up", 0.1, forged=212)
    assert row.text == "link up, 212 FORGED DROPPED" and row.color != link_row("up", 0.1).color


def stricter(library_data: dict[str, Any]) -> Library:
    """The unit library after an update: 'move' may go at most 1.5 m/s."""
    library_data["models"]["walker"]["skills"]["move"]["parameters"]["speed"]["max"] = 1.5
    return library_from_dict(library_data, "unit_team.yaml")


def test_a_parameter_the_library_refuses(gui: Gui, library_data: dict[str, Any]) -> None:
    feed = gui.feed
    fast = feed.add("alpha", "move", params={"speed": 1.8})
    feed.add("alpha", "move", params={"speed": 1.0})
    done = feed.add("bravo", "move", params={"speed": 1.9})
    feed.sync("bravo")
    feed("report_status", done, S.RUNNING)
    feed("report_status", done, S.SUCCESS)  # finished work is history, not a warning
    _warn_now(gui)
    assert gui.widget.messages.warnings == []
    gui.widget.on_library(stricter(library_data))
    _warn_now(gui)
    [warning] = gui.widget.messages.warnings
    assert warning.startswith("alpha's 'move': ") and "speed" in warning and "1.5" in warning
    feed("delete_skills", [fast])
    _warn_now(gui)
    assert gui.widget.messages.warnings == []


def test_parameter_checks_are_sliced_and_cover_only_changes(
    mission: Mission, library: Library, library_data: dict[str, Any]
) -> None:
    harness = Gui(mission, library)
    try:
        feed = harness.feed
        bad = [feed.add(agent, "move", params={"speed": 1.9}) for agent in ("alpha", "bravo")]
        for _ in range(200):
            feed.add("charlie", "move")
        view = harness.widget.view
        view.library = stricter(library_data)
        checker = alerts.ParameterChecker(budget=0.0)
        assert checker.warnings(view) == [] and checker.incomplete  # no time: nothing checked
        sliced = alerts.ParameterChecker(budget=0.0005)
        rounds = 0
        while True:
            found = sliced.warnings(view)
            rounds += 1
            if not sliced.incomplete:
                break
        assert rounds > 1
        assert len(found) == 2 and all("speed" in w for w in found)
        # Later, only what changed is checked again.
        feed("edit_skill", bad[0], {"speed": 1.0})
        sliced.note(feed.updates[-1].changed_ids)
        assert sliced.incomplete
        assert len(sliced.warnings(view)) == 1 and not sliced.incomplete
    finally:
        harness.close()


def _warn_now(gui: Gui) -> None:
    """Run the warnings pass now (the widget runs it 300 ms after changes)."""
    for _ in range(100):
        gui.widget.repaints.warn_now()
        if not gui.widget.repaints.checker.incomplete:
            return


def test_a_journal_alert_is_said_when_it_begins_and_when_it_clears(gui: Gui) -> None:
    log = gui.widget.messages.log

    def said() -> list[str]:
        return [log.item(i).text().split("  ", 1)[1] for i in range(log.count())]

    before = len(said())
    full = "the journal's disk is full: {} bytes free in /data: changes are refused"
    for free in (1000, 900, 800):  # the count changes every second: said once
        gui.widget.on_journal_alert(full.format(free))
    gui.widget.on_journal_alert("")
    assert said()[: len(said()) - before] == [
        "The journal's alert cleared: changes are recorded again.",
        f"Journal: {full.format(1000)}.",
    ]


def test_the_gui_and_the_server_warn_of_the_same_barriers(gui: Gui, mission: Mission) -> None:
    """One rule (rosmc_server.core.rules.advice): a partner being uploaded is on its way, not
    planned; the GUI's standing warning and the server's note on an upload agree."""
    from rosmc_server.core.rules.advice import unsynced_partners

    feed = gui.feed
    first, partner = feed.add("alpha", "wait"), feed.add("bravo", "wait")
    feed("add_barrier", [first, partner])
    feed.sync("alpha")
    assert len(alerts.barrier_warnings(gui.widget.view)) == 1
    assert len(unsynced_partners(mission.state, [first])) == 1
    feed.sync("bravo", confirm=False)  # bravo's upload awaits its (out-of-contact) robot
    assert alerts.barrier_warnings(gui.widget.view) == []
    assert unsynced_partners(mission.state, [first]) == []
