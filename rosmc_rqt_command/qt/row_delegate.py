"""Paints task rows so that a selected row keeps its status colour.

Qt's usual selection fills the row with the highlight colour, which would hide what
matters most: a selected failure must still look red. This delegate paints the row as
if unselected, then lays a light tint and a dark-blue frame over it.
"""

from __future__ import annotations

from python_qt_binding.QtCore import QModelIndex, QPoint
from python_qt_binding.QtGui import QColor, QPainter, QPen
from python_qt_binding.QtWidgets import QStyle, QStyledItemDelegate, QStyleOptionViewItem

SELECTION_FRAME = QColor("#0b3d91")
SELECTION_TINT = QColor(11, 61, 145, 38)


class RowDelegate(QStyledItemDelegate):  # type: ignore[misc]
    """Status colours under a selection frame (see the module docstring)."""

    def paint(self, painter: QPainter, option: QStyleOptionViewItem, index: QModelIndex) -> None:
        """Paint the cell unselected, then the selection's tint and frame."""
        selected = bool(option.state & QStyle.State_Selected)
        plain = QStyleOptionViewItem(option)
        plain.state &= ~(QStyle.State_Selected | QStyle.State_HasFocus)
        super().paint(painter, plain, index)
        if not selected:
            return
        rect = option.rect
        painter.save()
        painter.fillRect(rect, SELECTION_TINT)
        painter.setPen(QPen(SELECTION_FRAME, 2))
        top, bottom = rect.top() + 1, rect.bottom()
        painter.drawLine(QPoint(rect.left(), top), QPoint(rect.right(), top))
        painter.drawLine(QPoint(rect.left(), bottom), QPoint(rect.right(), bottom))
        if index.column() == 0:
            painter.drawLine(QPoint(rect.left() + 1, top), QPoint(rect.left() + 1, bottom))
        if index.column() == index.model().columnCount() - 1:
            painter.drawLine(QPoint(rect.right(), top), QPoint(rect.right(), bottom))
        painter.restore()
