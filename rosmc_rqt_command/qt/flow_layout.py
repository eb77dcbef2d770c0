"""A layout that places its items in a row and wraps them onto further rows when narrow.

The team bar's controls fit one row in a wide window; in a window half a screen wide they
take two, instead of forcing the window wider than its half of the screen.
"""

from __future__ import annotations

from python_qt_binding.QtCore import QPoint, QRect, QSize, Qt
from python_qt_binding.QtWidgets import QLayout, QLayoutItem, QWidget


class FlowLayout(QLayout):  # type: ignore[misc]
    """Items left to right, wrapped to the next row when the width runs out."""

    def __init__(self, parent: QWidget | None = None, spacing: int = 4) -> None:
        super().__init__(parent)
        self._items: list[QLayoutItem] = []
        self._gap = spacing

    def addItem(self, item: QLayoutItem) -> None:
        """Take ``item`` (called by ``addWidget``)."""
        self._items.append(item)

    def count(self) -> int:
        """How many items the layout holds."""
        return len(self._items)

    def itemAt(self, index: int) -> QLayoutItem | None:
        """The item at ``index`` (None past the end)."""
        return self._items[index] if 0 <= index < len(self._items) else None

    def takeAt(self, index: int) -> QLayoutItem | None:
        """Remove and return the item at ``index``."""
        return self._items.pop(index) if 0 <= index < len(self._items) else None

    def expandingDirections(self) -> Qt.Orientations:
        """It grows in neither direction by itself."""
        return Qt.Orientations(0)

    def hasHeightForWidth(self) -> bool:
        """Its height depends on its width (the rows it wraps into)."""
        return True

    def heightForWidth(self, width: int) -> int:
        """The height its items take when wrapped into ``width``."""
        return self._place(QRect(0, 0, width, 0), move=False)

    def setGeometry(self, rect: QRect) -> None:
        """Place the items in ``rect``."""
        super().setGeometry(rect)
        self._place(rect, move=True)

    def sizeHint(self) -> QSize:
        """All items in one row."""
        width = sum(item.sizeHint().width() + self._gap for item in self._items)
        height = max((item.sizeHint().height() for item in self._items), default=0)
        margins = self.contentsMargins()
        return QSize(width + margins.left() + margins.right(), height + margins.top() * 2)

    def minimumSize(self) -> QSize:
        """As wide as its widest item: everything else wraps."""
        size = QSize()
        for item in self._items:
            size = size.expandedTo(item.minimumSize())
        margins = self.contentsMargins()
        return size + QSize(margins.left() + margins.right(), margins.top() + margins.bottom())

    def _place(self, rect: QRect, move: bool) -> int:
        margins = self.contentsMargins()
        area = rect.adjusted(margins.left(), margins.top(), -margins.right(), -margins.bottom())
        x, y, row_height = area.x(), area.y(), 0
        for item in self._items:
            hint = _hint(item)
            if x + hint.width() > area.right() + 1 and row_height > 0:
                x, y, row_height = area.x(), y + row_height + self._gap, 0
            if move:
                item.setGeometry(QRect(QPoint(x, y), hint))
            x += hint.width() + self._gap
            row_height = max(row_height, hint.height())
        return int(y + row_height - rect.y() + margins.bottom())


def _hint(item: QLayoutItem) -> QSize:
    """The size ``item`` asks for: a widget's own hint, even if it ignores its hint in a row.

    (A label made with :func:`~.labels.never_widen` has an ``Ignored`` width, which Qt's
    item reports as 0; in a flow its text must still fit, or it is cut.)
    """
    widget = item.widget()
    hint = widget.sizeHint() if widget is not None else item.sizeHint()
    return hint.expandedTo(item.minimumSize()).boundedTo(item.maximumSize())
