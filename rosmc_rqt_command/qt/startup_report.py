"""When the command window's start-up stages ended, for ``rosmc_command --startup-report``.

A benchmark (bench/bench_command_gui_start.py) starts the window as a process and reads
this file to time, from the process start, the stages an operator waits through: the
imports (``main``), the ROS node (``node``), the empty window painted (``window``), the
mission snapshot received (``snapshot``), the first rows painted (``rows``) and every row
of the mission shown (``all``). Each stage is one JSON line ``{"stage": ..., "t": ...}``
with ``t`` in ``time.monotonic()`` seconds (one clock for every process of the machine).

Only a window started with the option watches its paints (an application event filter,
removed once the rows were painted): without it nothing here runs.
"""

from __future__ import annotations

import json
import sys
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from python_qt_binding.QtCore import QEvent, QObject, QTimer
from python_qt_binding.QtWidgets import QAbstractItemView, QApplication, QWidget

from ..core.view_state import ViewUpdate
from .task_widget import TaskWidget


class StartupReport(QObject):  # type: ignore[misc]
    """Appends each stage's end to ``path`` once (later marks of a stage are ignored).

    The ``rows`` and ``all`` lines also say how many robots' columns and rows the task
    held then (``columns``, ``rows``), and the ``all`` line lists the modules the process had
    imported by then (``modules``), so a test can tell what the start did not import.

    Args:
        path: The file to write (created anew).
    """

    def __init__(self, path: Path) -> None:
        super().__init__()
        self._path = path
        self._marked: set[str] = set()
        self._window: QWidget | None = None
        self._whole = False  # the first whole mission arrived
        self._tasks: TaskWidget | None = None
        path.write_text("")

    def mark(self, stage: str, when: float | None = None) -> None:
        """``stage`` ended ``when`` (``time.monotonic()`` seconds; default: now)."""
        if stage in self._marked:
            return
        self._marked.add(stage)
        line: dict[str, Any] = {"stage": stage, "t": time.monotonic() if when is None else when}
        if stage in ("rows", "all") and self._tasks is not None:
            tables = list(self._tasks.tables())
            line["columns"] = len(self._tasks.columns)
            line["rows"] = sum(table.section.rowCount() for table in tables)
        if stage == "all":
            line["modules"] = sorted(sys.modules)
        with self._path.open("a") as out:
            out.write(json.dumps(line) + "\n")

    def mark_soon(self, stage: str) -> None:
        """``stage`` ends when the event loop is next idle (the paint in progress is done)."""
        QTimer.singleShot(0, lambda: self.mark(stage))

    def watch(self, window: QWidget) -> None:
        """Mark ``window`` (its first paint) and ``rows`` (the first table painted with rows)."""
        self._window = window
        QApplication.instance().installEventFilter(self)

    def follow(self, updated: Any, tasks: TaskWidget) -> None:
        """Mark ``snapshot`` (when it was read) and ``all`` (every row of the first mission
        in ``tasks``) as the bridge's ``updated`` signal hands them over."""
        self._tasks = tasks
        updated.connect(self._on_updated)
        tasks.columns_added.connect(lambda _agents: self._mark_all_when_shown())

    def _on_updated(self, batch: Sequence[ViewUpdate]) -> None:
        resets = [update.received for update in batch if update.reset]
        if resets:
            self.mark("snapshot", resets[0])
            self._whole = True
            self._mark_all_when_shown()

    def _mark_all_when_shown(self) -> None:
        tasks = self._tasks
        if self._whole and "rows" in self._marked and tasks is not None and tasks.complete:
            self.mark_soon("all")

    def eventFilter(self, watched: QObject, event: QEvent) -> bool:
        """Note the paints the stages wait for; never consumes an event."""
        if event.type() != QEvent.Paint or not isinstance(watched, QWidget):
            return False
        window = self._window
        if window is not None and (watched is window or window.isAncestorOf(watched)):
            self.mark_soon("window")
        if _shows_rows(watched.parentWidget()):
            self.mark_soon("rows")
            QTimer.singleShot(0, self._mark_all_when_shown)
            QApplication.instance().removeEventFilter(self)
        return False


def _shows_rows(widget: QWidget | None) -> bool:
    """``widget`` is a task table with rows (its viewport is being painted)."""
    return (
        isinstance(widget, QAbstractItemView)
        and widget.objectName().startswith(("synced_", "blueprint_"))
        and widget.model() is not None
        and widget.model().rowCount() > 0
    )
