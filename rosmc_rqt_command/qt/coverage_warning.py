"""The non-modal warning in a robot's column that its task ends out of coverage.

The server words the warning (``AgentStatus.coverage_warning``): the robot's synchronized
task ends where the radio does not reach, and its lost-link policy would leave it there.
The label stays hidden while there is nothing to say.
"""

from __future__ import annotations

from python_qt_binding.QtWidgets import QLabel

from rosmc_server.core import AgentStatus

from .labels import never_widen

STYLE = (
    "QLabel { color:#7a4b00; background:#fff3cd; border:1px solid #e0a800;"
    " border-radius:3px; padding:2px; }"
)


def coverage_warning_label(agent: str) -> QLabel:
    """The (hidden) warning label of ``agent``'s column."""
    label = QLabel("")
    label.setObjectName(f"coverage_warning_{agent}")
    never_widen(label)
    label.setStyleSheet(STYLE)
    label.setVisible(False)
    return label


def show_coverage_warning(label: QLabel, status: AgentStatus | None) -> None:
    """Show the server's warning about the robot, or hide the label if there is none."""
    warning = status.coverage_warning if status is not None else ""
    label.setText(f"⚠ {warning[:1].upper()}{warning[1:]}" if warning else "")
    label.setToolTip(
        "Change the robot's lost-link policy (Link loss…) or its task, before it leaves "
        "coverage: out there nothing reaches it."
        if warning
        else ""
    )
    label.setVisible(bool(warning))
