"""The command GUI follows the mirror's deltas: no whole tasks copied, no rows compared.

A real :class:`~rosmc_server.core.Mission` makes random changes (operator requests and
robot answers, see ``test_legality.random_step``); each event goes through a real mirror,
:func:`~rosmc_rqt_command.core.view_state.view_update` and the real widget (offscreen).
After every change the view's tasks and sections, and each column's rows, equal the
mission's; a robot's status report reaches the GUI as one skill delta, not as its task.
"""

from __future__ import annotations

import random
from collections.abc import Iterator

import pytest

from rosmc_server.core import Library, Mission, RosmcError, SkillStatus
from rosmc_server.core.live.updates import SkillChanged
from rosmc_server.core.rules.legality import TaskView
from tests.unit.test_command_harness import Gui
from tests.unit.test_legality import ids, random_step


@pytest.fixture
def gui(library: Library) -> Iterator[Gui]:
    made = Gui(Mission(library, new_id=ids(), clock=lambda: 1.0), library)
    yield made
    made.close()


def assert_shown_as_the_mission(gui: Gui) -> None:
    state = gui.feed.mission.state
    for agent in state.agents:
        want = TaskView.of(state, agent)
        shown = gui.widget.view.view(agent)
        assert tuple(shown.skills) == want.skills, agent
        assert (shown.synced_end, shown.editable_start) == (want.synced_end, want.editable_start)
        assert (shown.uploading, shown.removing) == (want.uploading, want.removing), agent
        assert gui.table(agent, False).section.rows == list(want.synced), agent
        assert gui.table(agent, True).section.rows == list(want.blueprint), agent
        assert gui.widget.view.skills([s.id for s in want.skills]) == list(want.skills)


@pytest.mark.parametrize("seed", range(12))
def test_the_view_and_the_rows_follow_random_changes(gui: Gui, seed: int) -> None:
    rng = random.Random(seed)
    for _ in range(80):
        try:
            event = random_step(gui.feed.mission, rng)
        except RosmcError:
            continue  # refused: nothing to show
        if event is not None:
            gui.feed.mirror.on_event(event)
            assert_shown_as_the_mission(gui)


def test_a_status_report_arrives_as_one_delta(gui: Gui) -> None:
    first, second = gui.feed.add("alpha", "noop"), gui.feed.add("alpha", "noop")
    gui.feed.sync("alpha")
    gui.feed.updates.clear()
    gui.feed("report_status", first, SkillStatus.RUNNING)
    [update] = gui.feed.updates
    assert update.agents == ()  # no task copied
    [delta] = update.deltas
    assert isinstance(delta, SkillChanged) and delta.new.status is SkillStatus.RUNNING
    assert [s.id for s in gui.table("alpha", False).section.rows] == [first, second]
    assert gui.widget.view.skill(first).status is SkillStatus.RUNNING  # type: ignore[union-attr]
