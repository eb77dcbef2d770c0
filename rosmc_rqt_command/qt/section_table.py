"""A table of one section of a robot's task (on the robot, or planned): rows, selection, drops."""

from __future__ import annotations

from python_qt_binding.QtCore import Qt, Signal
from python_qt_binding.QtWidgets import QAbstractItemView, QHeaderView, QTableView, QWidget

from .row_delegate import RowDelegate
from .task_model import NUMBER, PARAMS, SKILL, STATUS, TAG, TaskModel

ROW_HEIGHT = 22
SKILL_WIDTH = 100
STATUS_WIDTH = 174
WIDTHS = ((TAG, 26), (NUMBER, 22), (SKILL, SKILL_WIDTH), (STATUS, STATUS_WIDTH))


class SectionTable(QTableView):  # type: ignore[misc]
    """A table of skills with row selection; a click on empty space clears it."""

    empty_clicked = Signal()
    plain_clicked = Signal()  # a row clicked without Ctrl or Shift

    def __init__(self, model: TaskModel, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.last_modifiers = Qt.NoModifier  # of the last click or key press here
        self.setModel(model)
        self.setItemDelegate(RowDelegate(self))
        self.setSelectionBehavior(QAbstractItemView.SelectRows)
        self.setSelectionMode(QAbstractItemView.ExtendedSelection)
        self.setContextMenuPolicy(Qt.CustomContextMenu)
        self.setEditTriggers(QAbstractItemView.NoEditTriggers)
        self.setWordWrap(False)
        self.setShowGrid(False)
        self.setAlternatingRowColors(False)
        self.setHorizontalScrollBarPolicy(Qt.ScrollBarAlwaysOff)
        rows = self.verticalHeader()
        rows.setVisible(False)
        rows.setSectionResizeMode(QHeaderView.Fixed)
        rows.setDefaultSectionSize(ROW_HEIGHT)
        columns = self.horizontalHeader()
        columns.setHighlightSections(False)
        for column, width in WIDTHS:
            columns.resizeSection(column, width)
        columns.setSectionResizeMode(PARAMS, QHeaderView.Stretch)
        self.compact = False
        if model.blueprint:
            self.setDragEnabled(True)
            self.setAcceptDrops(True)
            self.setDropIndicatorShown(True)
            self.setDragDropMode(QAbstractItemView.InternalMove)
            self.setDefaultDropAction(Qt.MoveAction)

    @property
    def section(self) -> TaskModel:
        """The model shown."""
        model: TaskModel = self.model()
        return model

    def set_compact(self, compact: bool) -> None:
        """Compact: no number or parameter cells; skill and status share the width."""
        self.compact = compact
        self.setColumnHidden(NUMBER, compact)
        self.setColumnHidden(PARAMS, compact)
        columns = self.horizontalHeader()
        mode = QHeaderView.Stretch if compact else QHeaderView.Interactive
        for column in (SKILL, STATUS):
            columns.setSectionResizeMode(column, mode)
        if not compact:
            for column, width in WIDTHS[2:]:
                columns.resizeSection(column, width)

    def mousePressEvent(self, event: object) -> None:
        """Clicking below the rows clears the selection (of every column)."""
        self.last_modifiers = event.modifiers()  # type: ignore[attr-defined]
        if not self.indexAt(event.pos()).isValid():  # type: ignore[attr-defined]
            self.empty_clicked.emit()
            return
        if not self.last_modifiers & (Qt.ControlModifier | Qt.ShiftModifier):
            self.plain_clicked.emit()
        super().mousePressEvent(event)

    def keyPressEvent(self, event: object) -> None:
        """Shift+arrows extend the selection across the keyboard too."""
        self.last_modifiers = event.modifiers()  # type: ignore[attr-defined]
        super().keyPressEvent(event)
