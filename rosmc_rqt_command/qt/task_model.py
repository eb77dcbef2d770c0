"""One section (synchronized or blueprint) of one robot's task, as a Qt table model.

:meth:`TaskModel.set_rows` takes the section's new skills and changes only the rows that
differ (same ids: ``dataChanged`` for the changed rows; otherwise the differing middle is
removed and inserted), so views keep their scroll position and unchanged rows their
selection. The blueprint model also accepts drops: a drag of its own rows asks for a new
order through :attr:`TaskModel.reorder_requested` instead of moving anything itself;
the server's answer moves the rows.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from python_qt_binding.QtCore import QAbstractTableModel, QMimeData, QModelIndex, Qt, Signal
from python_qt_binding.QtGui import QBrush, QColor, QFont

from rosmc_server.core import SkillInstance

from ..core import presentation
from ..core.mission_view import MissionView

MIME_TYPE = "application/x-rosmc-skill-ids"
SKILL_ID_ROLE = Qt.UserRole + 1

# Status before parameters: it is what an operator scans for; parameters take what is left.
TAG, NUMBER, SKILL, STATUS, PARAMS = range(5)
HEADERS = ("", "#", "Skill", "Status", "Details")


class TaskModel(QAbstractTableModel):  # type: ignore[misc]
    """The rows of one robot's synchronized section or blueprint.

    Args:
        agent: The robot.
        blueprint: This is the blueprint (editable, accepts drops) rather than the
            synchronized section.
        view: The mission view, asked for barrier tags and barrier partners.
    """

    reorder_requested = Signal(str, list)  # agent, new order of the editable blueprint ids

    def __init__(self, agent: str, blueprint: bool, view: MissionView, parent: object = None):
        super().__init__(parent)
        self.agent = agent
        self.blueprint = blueprint
        self._view = view
        self._rows: list[SkillInstance] = []
        self._offset = 0
        self._brushes: dict[str, QBrush] = {}
        self._italic = QFont()
        self._italic.setItalic(True)
        self._bold = QFont()
        self._bold.setBold(True)

    # -- content -----------------------------------------------------------------------------
    @property
    def rows(self) -> list[SkillInstance]:
        """The skills shown, top to bottom."""
        return list(self._rows)

    def skill_at(self, row: int) -> SkillInstance | None:
        """The skill of ``row`` (None if out of range)."""
        return self._rows[row] if 0 <= row < len(self._rows) else None

    def row_of(self, skill_id: str) -> int:
        """The row showing ``skill_id`` (-1 if none)."""
        for row, skill in enumerate(self._rows):
            if skill.id == skill_id:
                return row
        return -1

    def set_rows(self, skills: Sequence[SkillInstance], offset: int) -> None:
        """Show ``skills`` (numbered from ``offset`` + 1), changing as few rows as possible."""
        old, new = self._rows, list(skills)
        renumber = offset != self._offset
        self._offset = offset
        start = 0
        while start < min(len(old), len(new)) and old[start].id == new[start].id:
            start += 1
        end_old, end_new = len(old), len(new)
        while end_old > start and end_new > start and old[end_old - 1].id == new[end_new - 1].id:
            end_old -= 1
            end_new -= 1
        if end_old > start:
            self.beginRemoveRows(QModelIndex(), start, end_old - 1)
            self._rows = old[:start] + old[end_old:]
            self.endRemoveRows()
        if end_new > start:
            self.beginInsertRows(QModelIndex(), start, end_new - 1)
            self._rows = self._rows[:start] + new[start:end_new] + self._rows[start:]
            self.endInsertRows()
        self._rows = new
        kept = [*range(start), *range(end_new, len(new))]
        shift = end_old - end_new
        for row in kept:
            before = old[row if row < start else row + shift]
            if renumber or (before is not new[row] and before != new[row]):
                self._changed(row, row)

    def replace_row(self, row: int, skill: SkillInstance) -> bool:
        """Show ``skill`` in place of the same skill at ``row``; False if it is not there."""
        if not (0 <= row < len(self._rows)) or self._rows[row].id != skill.id:
            return False
        self._rows[row] = skill
        self._changed(row, row)
        return True

    def insert_row(self, row: int, skill: SkillInstance) -> bool:
        """Show ``skill`` as a new row ``row``; False if there is no such place."""
        if not 0 <= row <= len(self._rows):
            return False
        self.beginInsertRows(QModelIndex(), row, row)
        self._rows.insert(row, skill)
        self.endInsertRows()  # rows below move down: the view repaints them with their number
        return True

    def remove_row(self, row: int, skill_id: str) -> bool:
        """Stop showing ``skill_id``, at ``row``; False if it is not there."""
        if not (0 <= row < len(self._rows)) or self._rows[row].id != skill_id:
            return False
        self.beginRemoveRows(QModelIndex(), row, row)
        del self._rows[row]
        self.endRemoveRows()
        return True

    def refresh(self) -> None:
        """Repaint every row (barriers or robot statuses changed)."""
        if self._rows:
            self._changed(0, len(self._rows) - 1)

    def refresh_skill(self, skill_id: str) -> None:
        """Repaint the row of ``skill_id`` (if shown here)."""
        row = self.row_of(skill_id)
        if row >= 0:
            self._changed(row, row)

    def _changed(self, first: int, last: int) -> None:
        self.dataChanged.emit(self.index(first, 0), self.index(last, len(HEADERS) - 1))

    # -- Qt model interface ---------------------------------------------------------------------
    def rowCount(self, parent: QModelIndex = QModelIndex()) -> int:  # noqa: B008
        return 0 if parent.isValid() else len(self._rows)

    def columnCount(self, parent: QModelIndex = QModelIndex()) -> int:  # noqa: B008
        return 0 if parent.isValid() else len(HEADERS)

    def headerData(self, section: int, orientation: int, role: int = Qt.DisplayRole) -> object:
        if orientation == Qt.Horizontal and role == Qt.DisplayRole:
            return HEADERS[section]
        return None

    def data(self, index: QModelIndex, role: int = Qt.DisplayRole) -> object:
        skill = self.skill_at(index.row())
        if skill is None:
            return None
        column = index.column()
        if role == Qt.DisplayRole:
            return self._text(skill, index.row(), column)
        if role == Qt.BackgroundRole:
            number = self._view.barrier_number(skill.id)
            if column == TAG and number:
                return self._brush(presentation.barrier_colour(number))
            colour = presentation.row_colour(skill)
            if self._last_known(skill):
                colour = presentation.last_known_colour(colour)
            return self._brush(colour)
        if role == Qt.ForegroundRole:
            if column == TAG and self._view.barrier_number(skill.id):
                return self._brush("#ffffff")
            if self._last_known(skill):
                return self._brush(presentation.LAST_KNOWN_TEXT_COLOUR)
            return self._brush(presentation.text_colour(skill))
        if role == Qt.FontRole:
            if skill.transfer.value or self._last_known(skill):
                return self._italic
            if column == TAG or (column == STATUS and presentation.is_alarm(skill)):
                return self._bold
            return None
        if role == Qt.ToolTipRole:
            return self._tooltip(skill)
        if role == Qt.TextAlignmentRole and column in (TAG, NUMBER):
            return int(Qt.AlignCenter)
        if role == SKILL_ID_ROLE:
            return skill.id
        return None

    def _last_known(self, skill: SkillInstance) -> bool:
        return presentation.is_last_known(skill, self._view.out_of_contact(skill.agent))

    def flags(self, index: QModelIndex) -> Any:
        base = Qt.ItemIsEnabled | Qt.ItemIsSelectable
        if not index.isValid():
            return Qt.ItemIsDropEnabled if self.blueprint else Qt.NoItemFlags
        skill = self.skill_at(index.row())
        if self.blueprint and skill is not None and skill.is_editable:
            return base | Qt.ItemIsDragEnabled
        return base

    def supportedDropActions(self) -> Any:
        return Qt.MoveAction

    def mimeTypes(self) -> list[str]:
        return [MIME_TYPE]

    def mimeData(self, indexes: list[QModelIndex]) -> QMimeData:
        rows = sorted({index.row() for index in indexes})
        ids = [self._rows[row].id for row in rows if 0 <= row < len(self._rows)]
        mime = QMimeData()
        mime.setData(MIME_TYPE, "\n".join([self.agent, *ids]).encode())
        return mime

    def dropMimeData(
        self, mime: QMimeData, action: int, row: int, column: int, parent: QModelIndex
    ) -> bool:
        """Ask for the order the drop means; the rows move when the server agrees."""
        order = self.order_after_drop(mime, row, parent)
        if order is not None:
            self.reorder_requested.emit(self.agent, order)
        return False  # nothing moves here, so Qt removes nothing from the source

    def order_after_drop(self, mime: QMimeData, row: int, parent: QModelIndex) -> list[str] | None:
        """The editable blueprint's order if the dragged rows went before ``row``."""
        if not self.blueprint or not mime.hasFormat(MIME_TYPE):
            return None
        agent, *moved = bytes(mime.data(MIME_TYPE)).decode().split("\n")
        if agent != self.agent or not moved:
            return None
        if row < 0:
            row = parent.row() if parent.isValid() else len(self._rows)
        editable = [s.id for s in self._rows if s.is_editable]
        before = [s.id for s in self._rows[:row] if s.is_editable and s.id not in moved]
        rest = [i for i in editable if i not in moved and i not in before]
        order = [*before, *[i for i in moved if i in editable], *rest]
        return order if order != editable and len(order) == len(editable) else None

    # -- cells ----------------------------------------------------------------------------
    def _text(self, skill: SkillInstance, row: int, column: int) -> str:
        if column == TAG:
            number = self._view.barrier_number(skill.id)
            return f"B{number}" if number else ""
        if column == NUMBER:
            return str(self._offset + row + 1)
        if column == SKILL:
            return skill.label or skill.skill
        if column == PARAMS:
            return presentation.params_summary(skill)
        return self._view.status_text(skill)

    def _tooltip(self, skill: SkillInstance) -> str:
        lines = [f"{skill.label or skill.skill} — skill {skill.skill}, id {skill.id}"]
        number = self._view.barrier_number(skill.id)
        if number:
            barrier = self._view.barrier_of(skill.id)
            partners = [s.agent for s in self._view.skills(barrier.skill_ids if barrier else ())]
            lines.append(f"barrier B{number}: starts together with {', '.join(partners)}")
        lines.append(f"status: {self._view.status_text(skill)}")
        if skill.status_text:
            lines.append(skill.status_text)
        lines += [
            f"{name}: {presentation.value_summary(value)}" for name, value in skill.params.items()
        ]
        return "\n".join(lines)

    def _brush(self, colour: str) -> QBrush:
        brush = self._brushes.get(colour)
        if brush is None:
            brush = self._brushes[colour] = QBrush(QColor(colour))
        return brush
