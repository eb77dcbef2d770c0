"""The parameter panel's place rows: a Place picker under each location parameter and the
"Drive there first" button, and what choosing in them asks of the server.

Choosing a task marker binds the parameter (one ``edit_skill``); a region, the lander or a
robot sends its value; ``Typed coordinates`` unbinds. ``New marker here…`` asks the window
for a marker at the parameter's value, bound at once; ``Pick in 3D view…`` waits for the
next task marker made in rviz (the stock tools) and binds it.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from python_qt_binding.QtCore import QObject, Signal
from python_qt_binding.QtWidgets import QFormLayout

from rosmc_server.core import MarkerType, ParameterSpec, Pose, SkillInstance, TaskMarker
from rosmc_server.core.skills.params import value_to_data
from rosmc_server.core.views.places import Place, Surroundings

from ..core.mission_view import MissionView
from ..core.place_choices import drive_first_offer, offered
from .place_picker import DriveFirstButton, PlacePicker


@dataclass(frozen=True)
class Waiting:
    """A parameter waiting for the next task marker made in the 3D view."""

    skill_id: str
    param: str
    known: frozenset[str]


class PlaceRows(QObject):  # type: ignore[misc]
    """The pickers of the shown skill's location parameters, and its drive-first offer."""

    edit_requested = Signal(str, dict)  # skill id, edit_skill keyword arguments
    marker_requested = Signal(str, str, object)  # skill id, parameter, TaskMarker to bind
    drive_requested = Signal(object)  # a rosmc_server.core.views.drive_first.DriveFirst
    rename_requested = Signal(str, str)  # old marker name, new name
    said = Signal(str)  # a sentence for the message area

    def __init__(self, view: MissionView) -> None:
        super().__init__()
        self._view = view
        self.around: Callable[[], Surroundings] = Surroundings
        self.pickers: dict[str, PlacePicker] = {}
        self.drive_button = DriveFirstButton()
        self.drive_button.clicked.connect(self._on_drive_button_clicked)
        self.waiting: Waiting | None = None
        self._skill: SkillInstance | None = None
        self._offer: object = None

    def clear(self) -> None:
        """Forget the rows (the panel removed them, and their widgets with them)."""
        self.pickers = {}
        self.drive_button = DriveFirstButton()
        self._skill, self._offer = None, None

    def add_picker(self, form: QFormLayout, param: ParameterSpec) -> None:
        """Add the Place picker row of ``param`` (a location parameter) to ``form``."""
        picker = PlacePicker()
        picker.setObjectName(f"place_{param.name}")
        name = param.name
        picker.place_chosen.connect(lambda p, n=name: self._on_picker_place_chosen(n, p))
        picker.typed_chosen.connect(lambda n=name: self._send({"bindings": {n: None}}))
        picker.new_marker_requested.connect(lambda n=name: self._on_picker_new_marker(n))
        picker.pick_in_view_requested.connect(lambda n=name: self._on_picker_pick(n))
        picker.rename_requested.connect(self.rename_requested)
        picker.opening.connect(lambda n=name: self._show(n))
        form.addRow("   place", picker)
        self.pickers[name] = picker

    def add_drive_button(self, form: QFormLayout) -> None:
        """Add the "Drive there first" button (hidden until offered) to ``form``."""
        self.drive_button = DriveFirstButton()
        self.drive_button.clicked.connect(self._on_drive_button_clicked)
        form.addRow(self.drive_button)

    def fill(self, skill: SkillInstance, editable: bool) -> None:
        """Show ``skill``'s places and drive-first offer; bind a marker picked in 3D."""
        self._skill = skill
        for name in self.pickers:
            self._show(name)
        self._take_picked(skill)
        offer = drive_first_offer(self._view, self.around(), skill) if editable else None
        self._offer = offer
        self.drive_button.offer(offer.words if offer is not None else "")

    def _show(self, name: str) -> None:
        skill = self._skill
        if skill is None or name not in self.pickers:
            return
        places = offered(self._view, self.around(), skill, name)
        bound = skill.bindings.get(name, "")
        self.pickers[name].show_places(places, bound, skill.params.get(name))

    def _take_picked(self, skill: SkillInstance) -> None:
        waiting, library = self.waiting, self._view.library
        if waiting is not None and waiting.skill_id != skill.id:
            self.waiting = None  # another skill shown: the pick is off
            return
        if waiting is None or not skill.is_editable or library is None:
            return
        accepts = library.skill(skill.agent, skill.skill).parameter(waiting.param)
        new = [
            m
            for m in self._view.markers.values()
            if m.name not in waiting.known and accepts.accepts_marker(m.type)
        ]
        if new:
            self.waiting = None
            self._send({"bindings": {waiting.param: new[0].name}})

    def enable(self, editable: bool) -> None:
        """Let the operator choose, or not."""
        for picker in self.pickers.values():
            picker.setEnabled(editable)
        self.drive_button.setEnabled(editable)

    def _on_picker_place_chosen(self, name: str, place: Place) -> None:
        values, bindings = place.fill(name)
        if bindings:
            self._send({"bindings": bindings})
        else:
            self._send({"params": {k: value_to_data(v) for k, v in values.items()}})

    def _on_picker_new_marker(self, name: str) -> None:
        skill = self._skill
        if skill is None or self._view.library is None:
            return
        kind = self._view.library.skill(skill.agent, skill.skill).parameter(name).marker_type
        value = skill.params.get(name)
        if kind is MarkerType.AREA and isinstance(value, list):
            corners = tuple(Pose(float(v["x"]), float(v["y"])) for v in value)
            marker = TaskMarker("", kind, corners[0], corners)
        elif kind is not None and isinstance(value, Pose):
            marker = TaskMarker("", kind, value)
        else:
            return
        self.marker_requested.emit(skill.id, name, marker)

    def _on_picker_pick(self, name: str) -> None:
        skill = self._skill
        if skill is None:
            return
        self.waiting = Waiting(skill.id, name, frozenset(self._view.markers))
        self.said.emit(
            f"Click the place in rviz (Publish Point, or 2D Nav Goal for a heading); the new "
            f"marker fills {name} of '{skill.label or skill.skill}'."
        )

    def _on_drive_button_clicked(self) -> None:
        if self._offer is not None:
            self.drive_requested.emit(self._offer)

    def _send(self, fields: dict[str, object]) -> None:
        if self._skill is not None:
            self.edit_requested.emit(self._skill.id, fields)
