"""Parameter editors: every type shows a value and sends it back, keeps to its bounds, and
refuses what the library would refuse with a sentence (nothing is sent then).

The editors are driven through the parameter panel of the real widget, by typing and
clicking; what the panel sends is applied to the real mission, and the panel must then
show the mission's value.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from typing import Any

import pytest
from python_qt_binding.QtCore import Qt
from python_qt_binding.QtTest import QTest

from rosmc_rqt_command.core.requests import Answer, Request
from rosmc_rqt_command.qt.param_editors import (
    BoolEditor,
    ChoiceEditor,
    NumberEditor,
    PoseEditor,
    TextEditor,
    VertexEditor,
    make_editor,
)
from rosmc_server.core import InvalidRequest, Library, Mission, ParamType, Pose
from rosmc_server.core.skills.library import ParameterSpec
from tests.unit.test_command_harness import Gui, open_gui


@pytest.fixture
def gui(mission: Mission, library: Library) -> Iterator[Gui]:
    """A command widget following the ``mission`` fixture."""
    yield from open_gui(mission, library)


def shown(gui: Gui, agent: str, skill: str, **params: Any) -> str:
    """Add a skill and select it; its id."""
    skill_id = gui.feed.add(agent, skill, params=params or None)
    row = gui.ids(agent, True).index(skill_id)
    gui.click_row(agent, True, row)
    gui.app.processEvents()  # the new editors are laid out before anyone clicks them
    assert gui.widget.parameters.skill is not None
    assert gui.widget.parameters.skill.id == skill_id
    return skill_id


def type_into(line: Any, text: str) -> None:
    """Replace a line edit's text as a person does, then press Enter."""
    line.selectAll()
    QTest.keyClicks(line, text)
    QTest.keyClick(line, Qt.Key_Return)


def sent(gui: Gui) -> Request:
    """The one request sent since the last call; applied to the mission as the server would."""
    [request] = gui.backend.requests
    gui.backend.requests.clear()
    assert request.operation == "edit_skill"
    gui.feed("edit_skill", *request.args, **request.kwargs)
    return request


def refused(gui: Gui) -> str:
    """Nothing was sent; the message the operator got."""
    assert gui.backend.requests == []
    message = gui.widget.messages.messages()[0]
    assert "Not sent:" in message
    return message


def test_numbers_keep_to_their_bounds_and_units(gui: Gui) -> None:
    skill_id = shown(gui, "alpha", "move")
    editor = gui.widget.parameters.editors["speed"]
    assert isinstance(editor, NumberEditor)
    assert editor.spin.suffix() == " m/s"
    assert editor.spin.toolTip() == "allowed: 0.1 to 2 m/s"
    type_into(editor.spin.lineEdit(), "1.25")
    assert sent(gui).kwargs == {"params": {"speed": 1.25}}
    assert gui.feed.mission.state.skill(skill_id).params["speed"] == 1.25
    assert editor.value() == 1.25  # shown again from the mission
    type_into(editor.spin.lineEdit(), "7")  # above the maximum: refused with the range
    message = refused(gui)
    assert "must be at most 2, got 7 (allowed: 0.1 to 2 m/s)." in message, message
    assert editor.value() == 7.0 and editor.styleSheet()  # not changed behind one's back
    passes = shown(gui, "alpha", "scan")
    spin = gui.widget.parameters.editors["passes"].spin
    for typed, words in (("-5", "at least 1, got -5"), ("99999", "at most 5, got 99999")):
        type_into(spin.lineEdit(), typed)
        message = refused(gui)
        assert f"{words} (allowed: 1 to 5)." in message, message
        assert spin.value() == int(typed)
        gui.widget.messages.log.clear()
    type_into(spin.lineEdit(), "4")
    assert sent(gui).kwargs == {"params": {"passes": 4}}
    assert gui.feed.mission.state.skill(passes).params["passes"] == 4


def test_bool_choice_text_and_dict(gui: Gui) -> None:
    skill_id = shown(gui, "alpha", "wait")
    editors = gui.widget.parameters.editors
    verbose = editors["verbose"]
    assert isinstance(verbose, BoolEditor) and verbose.value() is False
    QTest.mouseClick(verbose.box, Qt.LeftButton)
    assert sent(gui).kwargs == {"params": {"verbose": True}}
    note = editors["note"]
    assert isinstance(note, TextEditor)
    type_into(note.line, "basalt near the ridge")
    assert sent(gui).kwargs == {"params": {"note": "basalt near the ridge"}}
    options = editors["options"]
    type_into(options.line, '{"exposure": 3, "filters": ["red"]}')
    assert sent(gui).kwargs == {"params": {"options": {"exposure": 3, "filters": ["red"]}}}
    params = gui.feed.mission.state.skill(skill_id).params
    assert params["verbose"] is True and params["options"] == {"exposure": 3, "filters": ["red"]}
    assert options.value() == {"exposure": 3, "filters": ["red"]}

    shown(gui, "alpha", "scan")
    mode = gui.widget.parameters.editors["mode"]
    assert isinstance(mode, ChoiceEditor)
    assert [mode.combo.itemText(i) for i in range(mode.combo.count())] == ["fast", "slow"]
    QTest.keyClick(mode.combo, Qt.Key_Down)
    assert sent(gui).kwargs == {"params": {"mode": "slow"}}


def test_bad_text_is_refused_with_a_sentence(gui: Gui) -> None:
    skill_id = shown(gui, "alpha", "wait")
    options = gui.widget.parameters.editors["options"]
    type_into(options.line, "[1, 2]")  # a list where a dict belongs
    message = refused(gui)
    assert "options" in message and message.rstrip().endswith(".")
    assert options.styleSheet()  # tinted while it cannot be sent
    type_into(options.line, "{unclosed")
    refused(gui)
    assert gui.feed.mission.state.skill(skill_id).params["options"] == {}
    type_into(options.line, '{"ok": true}')
    assert sent(gui).kwargs == {"params": {"options": {"ok": True}}}
    assert not options.styleSheet()


def test_pose_in_metres_and_degrees(gui: Gui) -> None:
    skill_id = shown(gui, "alpha", "move")
    pose = gui.widget.parameters.editors["target"]
    assert isinstance(pose, PoseEditor)
    assert pose.spins["yaw"].suffix() == "°" and pose.spins["x"].suffix() == " m"
    type_into(pose.spins["x"].lineEdit(), "12.5")
    assert sent(gui).kwargs["params"]["target"]["x"] == 12.5
    type_into(pose.spins["yaw"].lineEdit(), "90")
    data = sent(gui).kwargs["params"]["target"]
    assert data["yaw"] == pytest.approx(math.pi / 2) and data["x"] == 12.5
    target = gui.feed.mission.state.skill(skill_id).params["target"]
    assert isinstance(target, Pose) and target.yaw == pytest.approx(math.pi / 2)
    assert pose.spins["yaw"].value() == pytest.approx(90.0)
    type_into(pose.spins["roll"].lineEdit(), "400")  # beyond a half turn: the last 0 is refused
    assert sent(gui).kwargs["params"]["target"]["roll"] == pytest.approx(math.radians(40))


def test_area_corners_are_added_removed_and_checked(gui: Gui) -> None:
    skill_id = shown(gui, "alpha", "scan")
    area = gui.widget.parameters.editors["area"]
    assert isinstance(area, VertexEditor)
    assert area.table.rowCount() == 3
    QTest.mouseClick(area.add_button, Qt.LeftButton)
    corners = sent(gui).kwargs["params"]["area"]
    assert len(corners) == 4 and corners[-1] == {"x": 1.0, "y": 1.0}
    assert len(gui.feed.mission.state.skill(skill_id).params["area"]) == 4
    area.table.item(0, 0).setText("abc")  # a person typing a word into a corner
    message = refused(gui)
    assert "corner 1 needs a number for x, not 'abc'" in message
    area.table.item(0, 0).setText("-0.5")
    assert sent(gui).kwargs["params"]["area"][0] == {"x": -0.5, "y": 0.0}
    area.table.setCurrentCell(3, 0)
    QTest.mouseClick(area.remove_button, Qt.LeftButton)
    assert len(sent(gui).kwargs["params"]["area"]) == 3
    QTest.mouseClick(area.remove_button, Qt.LeftButton)  # two corners are no area
    message = refused(gui)
    assert "area" in message
    assert len(gui.feed.mission.state.skill(skill_id).params["area"]) == 3


def test_only_planned_skills_are_editable(gui: Gui) -> None:
    skill_id = shown(gui, "alpha", "wait")
    panel = gui.widget.parameters
    assert panel.editable and panel.label_edit.isEnabled()
    gui.feed.sync("alpha")
    gui.click_row("alpha", False, 0)
    assert panel.skill is not None and panel.skill.id == skill_id
    assert not panel.editable
    assert not panel.label_edit.isEnabled()
    assert not panel.editors["note"].line.isEnabled()


def test_label_time_limit_and_retries(gui: Gui) -> None:
    skill_id = shown(gui, "alpha", "wait")
    panel = gui.widget.parameters
    type_into(panel.label_edit, "rest at the lander")
    assert sent(gui).kwargs == {"label": "rest at the lander"}
    type_into(panel.retries_spin.lineEdit(), "2")
    assert sent(gui).kwargs == {"timeout": 0.0, "max_retries": 2}
    skill = gui.feed.mission.state.skill(skill_id)
    assert skill.label == "rest at the lander" and skill.max_retries == 2
    assert gui.cell("alpha", True, 0, 2, Qt.DisplayRole) == "rest at the lander"
    # Out of range or empty: refused in a sentence, the field left as typed and tinted.
    for spin, typed, words in (
        (panel.retries_spin, "-5", "from 0 to"),
        (panel.timeout_spin, "-5", "non-negative number, got -5.0 (0 s: no time limit)"),
    ):
        gui.widget.messages.log.clear()
        type_into(spin.lineEdit(), typed)
        assert words in refused(gui) and spin.value() == -5 and spin.styleSheet()
    panel.retries_spin.setValue(2)
    panel.timeout_spin.setValue(0)
    gui.widget.messages.log.clear()
    panel.label_edit.selectAll()
    QTest.keyClick(panel.label_edit, Qt.Key_Backspace)  # the operator empties the label
    QTest.keyClick(panel.label_edit, Qt.Key_Return)
    assert "a label cannot be empty (it stays 'rest at the lander')" in refused(gui)
    assert panel.label_edit.text() == "" and panel.label_edit.styleSheet()


def test_a_refused_edit_returns_to_the_servers_value(gui: Gui) -> None:
    skill_id = shown(gui, "alpha", "move", speed=1.5)
    panel = gui.widget.parameters
    speed = panel.editors["speed"].spin
    type_into(speed.lineEdit(), "0.5")
    [request] = gui.backend.requests
    gui.backend.requests.clear()
    assert speed.value() == 0.5  # a refusal brings no update: only the answer can revert
    gui.widget.on_answer(Answer(request, error="skill 'x' is RUNNING"))  # the server refuses
    assert speed.value() == 1.5  # the server's value, even in the focused field
    said = gui.widget.messages.messages()[0]
    assert said.endswith("Could not change speed of 'move': skill 'x' is RUNNING."), said
    speed.editingFinished.emit()  # as when the focus leaves the field: nothing sent again
    assert gui.backend.requests == []
    assert gui.feed.mission.state.skill(skill_id).params["speed"] == 1.5


@pytest.mark.parametrize(
    ("ptype", "value"),
    [
        (ParamType.BOOL, True),
        (ParamType.INT, -3),
        (ParamType.FLOAT, 2.5),
        (ParamType.STRING, "olivine"),
        (ParamType.LIST, ["a", 1]),
        (ParamType.DICT, {"k": [1, 2]}),
        (ParamType.POSE, Pose(1.0, -2.0, 0.5, 0.0, 0.0, 0.25)),
    ],
)
def test_every_type_round_trips(ptype: ParamType, value: Any, gui: Gui) -> None:
    spec = ParameterSpec("p", ptype, value)
    editor = make_editor(spec)
    editor.set_value(value)
    back = spec.check(editor.value(), "test")
    if isinstance(value, Pose):
        assert isinstance(back, Pose)
        fields = Pose.FIELDS
        assert [getattr(back, f) for f in fields] == pytest.approx(
            [getattr(value, f) for f in fields], abs=1e-3
        )  # angles are shown in 0.1° steps
    else:
        assert back == value


def test_unreadable_list_text_raises_a_sentence(gui: Gui) -> None:
    editor = make_editor(ParameterSpec("tags", ParamType.LIST, []))
    assert isinstance(editor, TextEditor)
    editor.line.setText("[unclosed")
    with pytest.raises(InvalidRequest) as caught:
        editor.value()
    assert "\n" not in str(caught.value) and str(caught.value)


def test_a_refused_label_tint_goes_with_the_selection(gui: Gui) -> None:
    shown(gui, "alpha", "wait")
    panel = gui.widget.parameters
    panel.label_edit.setFocus()
    panel.label_edit.selectAll()
    QTest.keyClick(panel.label_edit, Qt.Key_Backspace)
    QTest.keyClick(panel.label_edit, Qt.Key_Return)
    assert panel.label_edit.styleSheet(), "refused: tinted"
    gui.widget.actions_.clear_selection.trigger()  # the label field keeps the focus
    gui.app.processEvents()
    assert panel.skill is None
    assert panel.label_edit.styleSheet() == "" and panel.label_edit.text() == ""
    shown(gui, "alpha", "wait")  # the next selection starts clean too
    assert panel.label_edit.styleSheet() == ""
