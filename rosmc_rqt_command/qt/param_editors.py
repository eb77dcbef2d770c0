"""Typed editors for skill parameters, one per parameter type.

Every editor has ``value()`` (raw data, checked by the parameter's spec before it is
sent), ``set_value(value)``, ``set_read_only(flag)`` and a ``committed`` signal fired when
the operator finishes a change (Enter, focus out, a toggle or a choice). Angles are shown
in degrees; the mission keeps radians.
"""

from __future__ import annotations

import json
import math
from collections.abc import Sequence
from typing import Any

from python_qt_binding.QtCore import Signal
from python_qt_binding.QtWidgets import (
    QAbstractSpinBox,
    QCheckBox,
    QComboBox,
    QDoubleSpinBox,
    QGridLayout,
    QHBoxLayout,
    QHeaderView,
    QLabel,
    QLineEdit,
    QPushButton,
    QSizePolicy,
    QSpinBox,
    QTableWidget,
    QTableWidgetItem,
    QVBoxLayout,
    QWidget,
)

from rosmc_server.core import InvalidRequest, MarkerType, ParameterSpec, ParamType, Pose, Value
from rosmc_server.core.skills.params import parse_text

BIG = 1e9
INVALID_STYLE = "background:#ffd6d6"


class Editor(QWidget):  # type: ignore[misc]
    """Base of every parameter editor."""

    committed = Signal()

    def value(self) -> object:
        """The edited value as raw data (may raise InvalidRequest for unreadable text)."""
        raise NotImplementedError

    def set_value(self, value: Value) -> None:
        """Show ``value``."""
        raise NotImplementedError

    def set_read_only(self, read_only: bool) -> None:
        """Let the operator change the value, or not."""
        for child in self.findChildren(QWidget):
            child.setEnabled(not read_only)

    def mark_invalid(self, invalid: bool) -> None:
        """Tint the editor while its content cannot be sent."""
        self.setStyleSheet(INVALID_STYLE if invalid else "")


class BoolEditor(Editor):
    """A checkbox."""

    def __init__(self, spec: ParameterSpec) -> None:
        super().__init__()
        self.box = QCheckBox("yes")
        layout = QHBoxLayout(self)
        layout.setContentsMargins(0, 0, 0, 0)
        layout.addWidget(self.box)
        layout.addStretch(1)
        self.box.clicked.connect(self._on_box_clicked)

    def value(self) -> object:
        return bool(self.box.isChecked())

    def set_value(self, value: Value) -> None:
        self.box.setChecked(bool(value))

    def _on_box_clicked(self, _checked: bool) -> None:
        self.committed.emit()


class NumberEditor(Editor):
    """A spin box with the parameter's bounds and unit (whole numbers for INT)."""

    def __init__(self, spec: ParameterSpec) -> None:
        super().__init__()
        whole = spec.type is ParamType.INT
        self.spin: Any = QSpinBox() if whole else QDoubleSpinBox()
        low = spec.minimum if spec.minimum is not None else -BIG
        high = spec.maximum if spec.maximum is not None else BIG
        # The box takes any number: one outside the bounds is refused with them when sent
        # (a box kept to the bounds turns "-5" into 5 and "99999" into 9 without a word).
        wide_range(self.spin)
        if not whole:
            self.spin.setDecimals(3)
            self.spin.setSingleStep(0.1 if high - low <= 10 else 1.0)
        if spec.unit:
            self.spin.setSuffix(f" {spec.unit}")
        self.allowed = allowed_range(spec)
        self.spin.setToolTip(f"allowed: {self.allowed}")
        self.spin.setKeyboardTracking(False)
        layout = QHBoxLayout(self)
        layout.setContentsMargins(0, 0, 0, 0)
        layout.addWidget(self.spin)
        self.spin.editingFinished.connect(self.committed)

    def value(self) -> object:
        return (
            int(self.spin.value()) if isinstance(self.spin, QSpinBox) else float(self.spin.value())
        )

    def set_value(self, value: Value) -> None:
        self.spin.setValue(value)


def wide_range(spin: Any) -> None:
    """Let a spin box hold any number its type can (the mission rules check the bounds)."""
    if isinstance(spin, QSpinBox):
        spin.setRange(-(2**31), 2**31 - 1)
    else:
        spin.setRange(-BIG, BIG)
    spin.setCorrectionMode(QAbstractSpinBox.CorrectToPreviousValue)


def allowed_range(spec: ParameterSpec) -> str:
    """The numbers ``spec`` allows, in words, e.g. "1 to 30 m" or "at least 0"."""
    unit = f" {spec.unit}" if spec.unit else ""
    low, high = spec.minimum, spec.maximum
    if low is not None and high is not None:
        return f"{low:g} to {high:g}{unit}"
    if low is not None:
        return f"at least {low:g}{unit}"
    if high is not None:
        return f"at most {high:g}{unit}"
    return f"any number{unit}"


class ChoiceEditor(Editor):
    """A drop-down of the parameter's allowed values."""

    def __init__(self, spec: ParameterSpec) -> None:
        super().__init__()
        self.choices = list(spec.choices)
        self.combo = QComboBox()
        for choice in self.choices:
            self.combo.addItem(str(choice))
        layout = QHBoxLayout(self)
        layout.setContentsMargins(0, 0, 0, 0)
        layout.addWidget(self.combo)
        self.combo.activated.connect(self._on_combo_activated)

    def value(self) -> object:
        return self.choices[self.combo.currentIndex()]

    def set_value(self, value: Value) -> None:
        if value in self.choices:
            self.combo.setCurrentIndex(self.choices.index(value))

    def _on_combo_activated(self, _index: int) -> None:
        self.committed.emit()


class TextEditor(Editor):
    """One line of text; for LIST and DICT the text is JSON (or YAML), checked as typed."""

    def __init__(self, spec: ParameterSpec) -> None:
        super().__init__()
        self.type = spec.type
        self.line = QLineEdit()
        if spec.type in (ParamType.LIST, ParamType.DICT):
            example = '["a", "b"]' if spec.type is ParamType.LIST else '{"key": 1}'
            self.line.setPlaceholderText(f"JSON, e.g. {example}")
        layout = QHBoxLayout(self)
        layout.setContentsMargins(0, 0, 0, 0)
        layout.addWidget(self.line)
        self.line.editingFinished.connect(self.committed)

    def value(self) -> object:
        if self.type is ParamType.STRING:
            return self.line.text()
        return parse_text(self.type, self.line.text(), "the value")

    def set_value(self, value: Value) -> None:
        text = value if isinstance(value, str) else json.dumps(value)
        self.line.setText(text)


class PoseEditor(Editor):
    """x, y, z in metres and roll, pitch, yaw in degrees."""

    def __init__(self, spec: ParameterSpec) -> None:
        super().__init__()
        grid = QGridLayout(self)
        grid.setContentsMargins(0, 0, 0, 0)
        self.spins: dict[str, QDoubleSpinBox] = {}
        for position, name in enumerate(Pose.FIELDS):
            spin = QDoubleSpinBox()
            spin.setObjectName(name)
            spin.setMinimumWidth(70)  # three to a row must fit a narrow panel
            spin.setSizePolicy(QSizePolicy.Ignored, QSizePolicy.Fixed)
            spin.setKeyboardTracking(False)
            angle = position >= 3
            spin.setDecimals(1 if angle else 2)
            spin.setRange(-180.0, 180.0) if angle else spin.setRange(-10000.0, 10000.0)
            spin.setSuffix("°" if angle else " m")
            spin.editingFinished.connect(self.committed)
            row, column = divmod(position, 3)
            grid.addWidget(QLabel(name), row * 2, column)
            grid.addWidget(spin, row * 2 + 1, column)
            self.spins[name] = spin

    def value(self) -> object:
        return {
            name: math.radians(spin.value()) if name in ("roll", "pitch", "yaw") else spin.value()
            for name, spin in self.spins.items()
        }

    def set_value(self, value: Value) -> None:
        pose = value if isinstance(value, Pose) else Pose.from_any(value, "the pose")
        for name, spin in self.spins.items():
            number = getattr(pose, name)
            spin.setValue(math.degrees(number) if name in ("roll", "pitch", "yaw") else number)


class VertexEditor(Editor):
    """The corners of an area, one row each (x, y in metres), with add/remove buttons."""

    def __init__(self, spec: ParameterSpec) -> None:
        super().__init__()
        self.table = QTableWidget(0, 2)
        self.table.setHorizontalHeaderLabels(["x (m)", "y (m)"])
        self.table.horizontalHeader().setSectionResizeMode(QHeaderView.Stretch)
        self.table.verticalHeader().setDefaultSectionSize(22)
        self.table.setMinimumHeight(110)
        self.add_button = QPushButton("Add corner")
        self.remove_button = QPushButton("Remove corner")
        buttons = QHBoxLayout()
        buttons.addWidget(self.add_button)
        buttons.addWidget(self.remove_button)
        layout = QVBoxLayout(self)
        layout.setContentsMargins(0, 0, 0, 0)
        layout.addWidget(self.table)
        layout.addLayout(buttons)
        self._filling = False
        self.table.itemChanged.connect(self._on_table_item_changed)
        self.add_button.clicked.connect(self._on_add_button_clicked)
        self.remove_button.clicked.connect(self._on_remove_button_clicked)

    def value(self) -> object:
        corners = []
        for row in range(self.table.rowCount()):
            point = {}
            for column, axis in enumerate(("x", "y")):
                item = self.table.item(row, column)
                text = item.text() if item is not None else ""
                try:
                    point[axis] = float(text)
                except ValueError:
                    raise InvalidRequest(
                        f"corner {row + 1} needs a number for {axis}, not {text!r}"
                    ) from None
            corners.append(point)
        return corners

    def set_value(self, value: Value) -> None:
        points: Sequence[Any] = value if isinstance(value, list) else []
        self._filling = True
        try:
            self.table.setRowCount(len(points))
            for row, point in enumerate(points):
                for column, axis in enumerate(("x", "y")):
                    raw = point.get(axis, 0.0) if isinstance(point, dict) else 0.0
                    self.table.setItem(row, column, QTableWidgetItem(f"{float(raw):g}"))
        finally:
            self._filling = False

    def _on_table_item_changed(self, _item: object) -> None:
        if not self._filling:
            self.committed.emit()

    def _on_add_button_clicked(self) -> None:
        corners = self._current()
        last = corners[-1] if corners else {"x": 0.0, "y": 0.0}
        self.set_value([*corners, {"x": last["x"] + 1.0, "y": last["y"]}])
        self.committed.emit()

    def _on_remove_button_clicked(self) -> None:
        row = self.table.currentRow()
        corners = self._current()
        if corners:
            del corners[row if 0 <= row < len(corners) else -1]
            self.set_value(corners)
            self.committed.emit()

    def _current(self) -> list[dict[str, float]]:
        try:
            value = self.value()
        except InvalidRequest:
            return []
        return value if isinstance(value, list) else []


def make_editor(spec: ParameterSpec) -> Editor:
    """The editor that suits ``spec``."""
    if spec.choices:
        return ChoiceEditor(spec)
    if spec.type is ParamType.BOOL:
        return BoolEditor(spec)
    if spec.type in (ParamType.INT, ParamType.FLOAT):
        return NumberEditor(spec)
    if spec.type is ParamType.POSE:
        return PoseEditor(spec)
    if spec.type is ParamType.LIST and spec.marker_type is MarkerType.AREA:
        return VertexEditor(spec)
    return TextEditor(spec)
