"""The Place picker beside a location parameter: named places, a new marker, or typed values.

Entries, top to bottom: ``Typed coordinates`` (unbinds; the fields keep their values), the
named places (task markers first: picking one binds the parameter, so it follows the
marker; a region, the lander or a robot fills the value), ``New marker here…`` (a task
marker at the typed value, bound at once) and ``Pick in 3D view…`` (the next task marker
made in rviz fills the parameter). Typing a new name while a marker is bound renames it.
"""

from __future__ import annotations

from collections.abc import Sequence

from python_qt_binding.QtCore import Signal
from python_qt_binding.QtWidgets import QComboBox, QPushButton, QSizePolicy

from rosmc_server.core.views.places import Place

TYPED = "Typed coordinates"
NEW_MARKER = "New marker here\u2026"
PICK_IN_VIEW = "Pick in 3D view\u2026"


class PlacePicker(QComboBox):  # type: ignore[misc]
    """Which place fills one location parameter (see the module docstring)."""

    place_chosen = Signal(object)  # a rosmc_server.core.views.places.Place
    typed_chosen = Signal()
    new_marker_requested = Signal()
    pick_in_view_requested = Signal()
    rename_requested = Signal(str, str)  # old name, new name
    opening = Signal()  # the list is about to open: offer the places as they are now

    def __init__(self) -> None:
        super().__init__()
        self.setEditable(True)
        self.setInsertPolicy(QComboBox.NoInsert)
        self.setMaxVisibleItems(20)
        self.setSizeAdjustPolicy(QComboBox.AdjustToMinimumContentsLengthWithIcon)
        self.setMinimumContentsLength(18)
        self.setSizePolicy(QSizePolicy.Expanding, QSizePolicy.Fixed)
        self.setToolTip(
            "Pick a place: a task marker binds the parameter (it follows the marker); a "
            "region, the lander or a robot fills its value. Type a new name to rename the "
            "bound marker."
        )
        self.places: list[Place] = []
        self._bound = ""
        self._current = -1
        self.activated.connect(self._on_picker_activated)
        self.lineEdit().returnPressed.connect(self._on_picker_return_pressed)

    def show_places(self, places: Sequence[Place], bound: str, value: object) -> None:
        """Offer ``places``; ``bound`` is the marker bound now ("" if none) and ``value``
        the parameter's value (a place that gives exactly it is shown as chosen)."""
        current = next((i for i, p in enumerate(places) if bound and p.marker == bound), -1)
        if current < 0 and not bound:
            current = next((i for i, p in enumerate(places) if p.value == value), -1)
        same = list(places) == self.places and (bound, current) == (self._bound, self._current)
        if (same and self.currentIndex() == current + 1) or self.view().isVisible():
            return  # unchanged, or the list is open: leave what the operator is doing alone
        self.places, self._bound, self._current = list(places), bound, current
        self.blockSignals(True)
        self.clear()
        self.addItem(TYPED)
        self.addItems([p.label for p in places])
        self.addItems([NEW_MARKER, PICK_IN_VIEW])
        self.setCurrentIndex(current + 1)
        self.blockSignals(False)
        # the list as wide as its longest entry, even where the panel is narrow
        self.view().setMinimumWidth(self.view().sizeHintForColumn(0) + 24)

    def showPopup(self) -> None:
        """Bring the places up to date (robots move), then open the list."""
        self.opening.emit()
        super().showPopup()

    def index_of(self, name: str) -> int:
        """The entry of the place called ``name`` (-1: none)."""
        return next((i + 1 for i, p in enumerate(self.places) if p.name == name), -1)

    def _on_picker_activated(self, index: int) -> None:
        count = len(self.places)
        if index == count + 1:
            self.new_marker_requested.emit()
        elif index == count + 2:
            self.pick_in_view_requested.emit()
        elif index <= 0:
            if self._bound:
                self.typed_chosen.emit()
        elif index - 1 != self._current:
            self.place_chosen.emit(self.places[index - 1])
        if index > count:  # an action, not a choice: show what holds again
            self.setCurrentIndex(self._current + 1)

    def _on_picker_return_pressed(self) -> None:
        text = self.currentText().strip()
        old = self._bound
        named = self.index_of(text)
        if named > 0 and text != old:  # a place's name typed: as if chosen
            self._on_picker_activated(named)
        elif text and old and text != old and self.findText(text) < 0:
            self._bound = text  # asked once, even if Enter reaches here twice
            self.rename_requested.emit(old, text)


class DriveFirstButton(QPushButton):  # type: ignore[misc]
    """Offers the robot's move before the shown skill, bound to the same place."""

    def __init__(self) -> None:
        super().__init__()
        self.setObjectName("drive_first")
        self.setToolTip(
            "Add the robot's move just before this skill, to the same place (the robot is "
            "not going there yet)"
        )
        self.hide()

    def offer(self, words: str) -> None:
        """Offer the move described by ``words`` ("" hides the button)."""
        self.setText(f"Drive there first: {words}" if words else "")
        self.setVisible(bool(words))
