"""The File menu: when the operator is asked about unsaved changes, and what each answer does.

Requests the widget sends are answered as the server would, with the real mission and
the real mission-file format (``rosmc_server.core.files.persistence``).
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path
from types import SimpleNamespace

import pytest

from rosmc_rqt_command.core.requests import Answer, Request
from rosmc_server.core import Library, Mission, SkillStatus
from rosmc_server.core.files.persistence import dump_mission, parse_mission
from tests.unit.test_command_harness import Gui, open_gui


@pytest.fixture
def gui(mission: Mission, library: Library) -> Iterator[Gui]:
    """A command widget following the ``mission`` fixture."""
    yield from open_gui(mission, library)


class Operator:
    """Answers the unsaved-changes question; remembers each time it was asked."""

    def __init__(self, gui: Gui) -> None:
        self.asked: list[str] = []
        self.answer = "cancel"
        gui.widget.files.ask = self._ask

    def _ask(self, doing: str) -> str:
        self.asked.append(doing)
        return self.answer


def serve(gui: Gui, answer_first: bool = False) -> list[str]:
    """Answer every pending request as the mission server would; the operations.

    ``answer_first``: a load's answer reaches the window before the mission event does.
    """
    mission = gui.feed.mission
    done = []
    while gui.backend.requests:
        request: Request = gui.backend.requests.pop(0)
        done.append(request.operation)
        if request.operation == "save_mission":
            document = dump_mission(mission.state.content(), mission.revision)
            value = SimpleNamespace(revision=mission.revision, document=document)
        elif request.operation == "load_mission":
            content, _ = parse_mission(request.kwargs["document"], mission.library, "test")
            if answer_first:
                value = mission.load(content, "test")
                gui.widget.on_answer(Answer(request, value=value))
                gui.feed.mirror.on_event(value)
                continue
            value = gui.feed("load", content, "test")
        elif request.operation == "new_mission":
            value = gui.feed("new_mission")
        else:
            raise AssertionError(f"unexpected {request.operation}")
        gui.widget.on_answer(Answer(request, value=value))
    return done


def test_an_empty_mission_is_replaced_without_a_question(gui: Gui) -> None:
    operator = Operator(gui)
    gui.widget.files.new_mission()
    assert operator.asked == []
    assert serve(gui) == ["new_mission"]


def test_unsaved_work_asks_and_cancel_keeps_it(gui: Gui) -> None:
    operator = Operator(gui)
    gui.feed.add("alpha", label="first sample")
    gui.widget.actions_.file["new"].trigger()  # the menu entry (Ctrl+N)
    assert operator.asked == ["starting a new mission"]
    assert gui.backend.requests == []  # cancelled: nothing sent
    operator.answer = "discard"
    gui.widget.files.new_mission()
    assert serve(gui) == ["new_mission"]
    assert gui.ids("alpha", True) == []
    assert not gui.widget.files.dirty


def test_save_then_only_plan_changes_count(gui: Gui, tmp_path: Path) -> None:
    operator = Operator(gui)
    feed = gui.feed
    skill = feed.add("alpha", "wait", label="rest")
    path = tmp_path / "plan.yaml"
    gui.widget.files.save_local(str(path))
    assert serve(gui) == ["save_mission"]
    assert path.read_text().startswith(dump_mission(feed.mission.state.content(), 0)[:12])
    assert not gui.widget.files.dirty
    assert any(f"Saved the mission to {path}" in m for m in gui.widget.messages.messages())
    # Robot progress is not a change of the plan.
    feed.sync("alpha")
    feed("report_status", skill, SkillStatus.RUNNING)
    feed("report_status", skill, SkillStatus.SUCCESS)
    assert not gui.widget.files.dirty
    gui.widget.files.new_mission()
    assert operator.asked == []
    gui.backend.requests.clear()
    # A new label is.
    feed.add("bravo", "wait")
    assert gui.widget.files.dirty
    # "Save" answers the question: saved where it was saved before, then replaced.
    operator.answer = "save"
    gui.widget.files.new_mission()
    assert operator.asked == ["starting a new mission"]
    assert serve(gui) == ["save_mission", "new_mission"]
    content, _ = parse_mission(path.read_text(), feed.mission.library, str(path))
    assert [s.skill for s in content.tasks["bravo"]] == ["wait"]


@pytest.mark.parametrize("answer_first", [False, True])
def test_a_barrier_is_a_change_and_an_opened_file_counts_as_saved(
    gui: Gui, tmp_path: Path, answer_first: bool
) -> None:
    operator = Operator(gui)
    feed = gui.feed
    a, b = feed.add("alpha", "wait"), feed.add("bravo", "wait")
    path = tmp_path / "team.yaml"
    gui.widget.files.save_local(str(path))
    serve(gui)
    feed("add_barrier", [a, b])
    assert gui.widget.files.dirty
    operator.answer = "discard"
    gui.widget.files.open_local(str(path))  # what the Open dialog leads to
    assert operator.asked == []  # open_local itself does not ask; the menu entry does
    assert serve(gui, answer_first) == ["load_mission"]
    assert gui.widget.files.location == ("local", str(path))
    assert not gui.widget.files.dirty
    assert gui.widget.view.barriers == ()


def test_an_unreadable_file_is_a_sentence(gui: Gui, tmp_path: Path) -> None:
    gui.widget.files.open_local(str(tmp_path / "missing.yaml"))
    assert gui.backend.requests == []
    [message] = [m for m in gui.widget.messages.messages() if "Cannot read" in m]
    assert "missing.yaml" in message and "\n" not in message
