"""What the window shows on a timer, not on every update: robot reports and warnings.

Robots report at up to 10 Hz each; their headers and buttons follow at most every
:data:`STATUS_REPAINT_MS`. Warnings (barriers, coverage, invalid parameters) are worked
out :data:`WARN_DELAY_MS` after the last change, a big mission's parameters a slice at a
time (:class:`~..core.alerts.ParameterChecker`).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable

from python_qt_binding.QtCore import QObject, QTimer

from rosmc_server.core import AgentStatus

from ..core import alerts, holding
from ..core.mission_view import MissionView
from .message_area import MessageArea

STATUS_REPAINT_MS = 200
WARN_DELAY_MS = 300
WARN_SLICE_MS = 50  # the rest of a big mission's parameter check follows this soon

ShowStatuses = Callable[[list[AgentStatus]], None]


class Repaints(QObject):  # type: ignore[misc]
    """The status and warning timers of one window.

    Args:
        view: The mission as shown.
        messages: Where the warnings go.
        show_statuses: Shows collected robot reports (headers, buttons) at once.
    """

    def __init__(
        self, view: MissionView, messages: MessageArea, show_statuses: ShowStatuses
    ) -> None:
        super().__init__()
        self._view = view
        self._messages = messages
        self._show_statuses = show_statuses
        self.checker = alerts.ParameterChecker()
        self._pending: dict[str, AgentStatus] = {}
        self.status_timer = self._timer(STATUS_REPAINT_MS, self.show_statuses_now)
        self.warn_timer = self._timer(WARN_DELAY_MS, self.warn_now)

    def _timer(self, interval: int, slot: Callable[[], None]) -> QTimer:
        timer = QTimer(self)
        timer.setSingleShot(True)
        timer.setInterval(interval)
        timer.timeout.connect(slot)
        return timer

    def note_statuses(self, statuses: Iterable[AgentStatus]) -> None:
        """Robot reports to show when the status timer fires (the latest per robot)."""
        for status in statuses:
            self._pending[status.agent] = status
        if self._pending and not self.status_timer.isActive():
            self.status_timer.start()

    def warn_soon(self) -> None:
        """Work the warnings out again shortly (once for a burst of changes)."""
        if not self.warn_timer.isActive():
            self.warn_timer.start(WARN_DELAY_MS)

    def show_statuses_now(self) -> None:
        """Show the collected robot reports now (the status timer's slot)."""
        statuses, self._pending = self._pending, {}
        self._show_statuses(list(statuses.values()))
        self.warn_soon()

    def warn_now(self) -> None:
        """Show every warning now (the warning timer's slot)."""
        view = self._view
        holds = holding.holds(view)
        warnings = [
            *(hold.sentence() for hold in holds),
            *alerts.barrier_warnings(view),
            *alerts.coverage_warnings(view),
            *alerts.radio_warnings(view),
            *self.checker.warnings(view),
        ]
        self._messages.show_warnings(warnings)
        self._messages.show_holds([hold.agent for hold in holds])
        if self.checker.incomplete:
            self.warn_timer.start(WARN_SLICE_MS)
