"""One robot's column of the task panel: header, synchronized section, blueprint, buttons.

The header names the robot and says how it is (link, seconds since heard, battery, Wi-Fi,
lost-link policy). Above the line: what is on the robot; below: the blueprint, which
can be reordered by drag and drop. The buttons act on this robot; they are enabled by
:meth:`AgentColumn.set_legal`.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from html import escape

from python_qt_binding.QtCore import QSize, Qt, Signal
from python_qt_binding.QtGui import QIcon
from python_qt_binding.QtWidgets import (
    QFrame,
    QGridLayout,
    QHBoxLayout,
    QLabel,
    QMenu,
    QSizePolicy,
    QStyle,
    QToolButton,
    QVBoxLayout,
    QWidget,
)

from rosmc_server.core import AgentStatus, LostLinkPolicy, PolicyInForce, SkillStatus
from rosmc_server.core.live.updates import SkillAdded, SkillChanged, SkillRemoved
from rosmc_server.core.robots.link import LinkStatus
from rosmc_server.core.robots.waiting import duration_text
from rosmc_server.core.rules.legality import TaskView

from ..core import presentation
from ..core.holding import barrier_wait, lost_link_hold
from ..core.legality import RobotAction
from ..core.mission_view import MissionView
from ..core.view_state import SkillDelta
from .coverage_warning import coverage_warning_label, show_coverage_warning
from .hold_notice import HoldNotice
from .labels import never_widen
from .policy_dialog import ask_policy
from .section_table import SectionTable
from .task_model import TaskModel

# A column is at least this wide (more robots than fit: the task panel scrolls sideways)
# and at most that wide (few robots: the columns share the width).
COLUMN_WIDTH = 330
MAX_COLUMN_WIDTH = 460
# Compact mode (a large team): narrower columns without the number and parameter cells.
COMPACT_WIDTH = 222
COMPACT_MAX_WIDTH = 226
# The robot's name and the blueprint's caption, by compact or not.
NAME_STYLE = {
    False: "<b style='font-size:13pt'>{agent}</b>",
    True: "<b style='font-size:10.5pt'>{agent}</b>",
}
BLUEPRINT_CAPTION = {
    False: "<i>Planned (not sent yet, editable)</i>",
    True: "<i>Planned (not sent yet)</i>",
}
SEND_TEXT = {False: "Send to robot…", True: "Send…"}
# The robot controls, written out (an operator should not have to know the icons).
CONTROLS = (
    (RobotAction.START, "Start"),
    (RobotAction.PAUSE, "Pause"),
    (RobotAction.RESUME, "Resume"),
    (RobotAction.STOP, "Stop"),
)
ON_ROBOT = "<i>On the robot</i>"
# agent, its skills, parent, the policy in force as reported[, the policy waiting]
AskPolicy = Callable[..., LostLinkPolicy | None]


class AgentColumn(QFrame):  # type: ignore[misc]
    """The task column of one robot."""

    robot_action = Signal(str, object)  # agent, RobotAction
    add_requested = Signal(str, str)  # agent, skill name
    policy_chosen = Signal(str, object)  # agent, LostLinkPolicy

    def __init__(self, agent: str, view: MissionView, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.agent = agent
        self._view = view
        self._out_of_contact = False  # as the rows last showed it
        self.setObjectName(f"column_{agent}")
        self.setFrameShape(QFrame.StyledPanel)
        self.setMinimumWidth(COLUMN_WIDTH)
        self.setMaximumWidth(MAX_COLUMN_WIDTH)
        self.setSizePolicy(QSizePolicy.Expanding, QSizePolicy.Preferred)
        self.synced_model = TaskModel(agent, False, view, self)
        self.blueprint_model = TaskModel(agent, True, view, self)
        self.synced_table = SectionTable(self.synced_model, self)
        self.blueprint_table = SectionTable(self.blueprint_model, self)
        self.synced_table.setObjectName(f"synced_{agent}")
        self.blueprint_table.setObjectName(f"blueprint_{agent}")

        self.name_label = QLabel(NAME_STYLE[False].format(agent=agent))
        self.name_label.setToolTip(agent)
        self.status_label = QLabel(presentation.link_summary(None))
        never_widen(self.status_label)
        self.status_label.setObjectName(f"status_{agent}")
        self.warning_label = coverage_warning_label(agent)
        self.wait_label = never_widen(QLabel(""))  # what its barrier waits for, how long
        self.wait_label.setObjectName(f"barrier_wait_{agent}")
        self.wait_label.setStyleSheet("QLabel { color:#8a5a00; }")
        self.wait_label.hide()
        self.hold_notice = HoldNotice(agent, self)
        self.hold_notice.resume_requested.connect(self._on_hold_notice_resume_requested)
        self.policy_in_force: PolicyInForce | None = None  # as the robot reports it
        self.default_policy: LostLinkPolicy | None = None  # the library's, for its model
        self.pending_policy: LostLinkPolicy | None = None  # chosen here, not yet in force
        self.skill_names: list[str] = []
        self.ask_policy: AskPolicy = ask_policy  # tests answer the dialog through this
        self.policy_button = self._tool(
            "Link loss…", "", "Choose what the robot does when it loses contact with the ground"
        )
        self.policy_button.setObjectName(f"policy_{agent}")
        self._link_icon = self.style().standardIcon(QStyle.SP_DriveNetIcon)
        self.policy_button.clicked.connect(self._on_policy_button_clicked)

        self.add_menu = QMenu(self)
        self.add_button = self._tool("Add skill", "", f"Add a skill to {agent}'s plan")
        self.add_button.setMenu(self.add_menu)
        self.add_button.setPopupMode(QToolButton.InstantPopup)
        self.add_menu.triggered.connect(self._on_add_menu_triggered)
        self.buttons: dict[RobotAction, QToolButton] = {
            RobotAction.SYNC_ALL: self._tool(
                SEND_TEXT[False], "", f"Send {agent}'s whole plan to the robot (asks first)"
            ),
        }
        for action, text in CONTROLS:
            self.buttons[action] = self._tool(text, "", f"{text} {agent}")
        for action, button in self.buttons.items():
            button.setObjectName(f"{action.value}_{agent}")
            button.clicked.connect(lambda _=False, a=action: self.robot_action.emit(self.agent, a))

        header = QVBoxLayout()
        top = QHBoxLayout()
        top.addWidget(self.name_label)
        top.addStretch(1)
        top.addWidget(self.policy_button)
        header.addLayout(top)
        header.addWidget(self.status_label)
        header.addWidget(self.warning_label)
        header.addWidget(self.wait_label)
        header.addWidget(self.hold_notice)
        # Adding and sending sit at opposite ends of their row, the controls on a row of
        # their own: a click meant for one never lands on the other.
        plan = QHBoxLayout()
        plan.addWidget(self.add_button)
        plan.addStretch(1)
        plan.addWidget(self.buttons[RobotAction.SYNC_ALL])
        bar = self._bar = QGridLayout()
        self._place_controls(compact=False)
        layout = QVBoxLayout(self)
        layout.setContentsMargins(4, 4, 4, 4)
        layout.addLayout(header)
        self.blueprint_caption = QLabel(BLUEPRINT_CAPTION[False])
        self.synced_caption = never_widen(QLabel(ON_ROBOT))
        self.synced_caption.setObjectName(f"synced_caption_{agent}")
        layout.addWidget(self.synced_caption)
        layout.addWidget(self.synced_table, 2)
        layout.addWidget(self.blueprint_caption)
        layout.addWidget(self.blueprint_table, 3)
        layout.addLayout(plan)
        layout.addLayout(bar)

    def _tool(self, text: str, icon: str, tip: str) -> QToolButton:
        button = QToolButton(self)
        if icon:
            button.setIcon(self.style().standardIcon(getattr(QStyle, icon)))
            button.setIconSize(QSize(16, 16))
        if text:
            button.setText(text)
            button.setToolButtonStyle(Qt.ToolButtonTextBesideIcon)
        button.setToolTip(tip)
        button.setAutoRaise(False)
        return button

    def _place_controls(self, compact: bool) -> None:
        """Start, Pause, Resume, Stop in a row; two rows of two in a compact column."""
        for position, (action, _text) in enumerate(CONTROLS):
            row, column = divmod(position, 2) if compact else (0, position)
            self._bar.addWidget(self.buttons[action], row, column)
        self._bar.setColumnStretch(4, 0 if compact else 1)
        self._bar.setColumnStretch(2, 1 if compact else 0)

    @property
    def tables(self) -> tuple[SectionTable, SectionTable]:
        """The synchronized table and the blueprint table."""
        return self.synced_table, self.blueprint_table

    @property
    def compact(self) -> bool:
        """The column is in compact mode."""
        return self.synced_table.compact

    def set_compact(self, compact: bool) -> None:
        """Narrow the column and drop its number and parameter cells (or bring them back)."""
        if compact == self.compact:
            return
        self.setMinimumWidth(COMPACT_WIDTH if compact else COLUMN_WIDTH)
        self.setMaximumWidth(COMPACT_MAX_WIDTH if compact else MAX_COLUMN_WIDTH)
        for table in self.tables:
            table.set_compact(compact)
        self.add_button.setText("+" if compact else "Add skill")
        self.buttons[RobotAction.SYNC_ALL].setText(SEND_TEXT[compact])
        self._place_controls(compact)
        self.hold_notice.resume_button.setText("Resume" if compact else f"Resume {self.agent}")
        # Compact, the robot's name needs the room: the policy button shows an icon only.
        self.policy_button.setText("" if compact else "Link loss…")
        self.policy_button.setIcon(self._link_icon if compact else QIcon())
        self.policy_button.setToolButtonStyle(
            Qt.ToolButtonIconOnly if compact else Qt.ToolButtonTextBesideIcon
        )
        self.name_label.setText(NAME_STYLE[compact].format(agent=self.agent))
        self.blueprint_caption.setText(BLUEPRINT_CAPTION[compact])
        self._bar.setSpacing(1 if compact else -1)  # -1: the style's spacing

    def show_task(self, task: TaskView) -> None:
        """Show the robot's task (only rows that changed are touched)."""
        self.synced_model.set_rows(task.synced, 0)
        self.blueprint_model.set_rows(task.blueprint, task.synced_end)

    def apply(self, task: TaskView, deltas: Sequence[SkillDelta]) -> None:
        """Show ``task`` after ``deltas``: row by row where the sections keep their bounds
        (a status report, a blueprint edit), else by comparing rows (:meth:`show_task`)."""
        synced_end = len(self.synced_model.rows)
        if synced_end != task.synced_end or not all(
            _row_edit(delta, synced_end, self.synced_model, self.blueprint_model)
            for delta in deltas
        ):
            self.show_task(task)

    def show_status(self, status: AgentStatus | None) -> None:
        """Show the robot's link and telemetry in the header."""
        text = presentation.link_summary(status)
        colour = "#a00000" if status is not None and status.link is LinkStatus.DOWN else "#333333"
        self.status_label.setText(f"<span style='color:{colour}'>{text}</span>")
        self.status_label.setToolTip(presentation.link_details(status))
        out_of_contact = self._view.out_of_contact(self.agent)
        if out_of_contact != self._out_of_contact:  # transfers now wait (or go): say so
            self._out_of_contact = out_of_contact
            self.synced_model.refresh()
            self.blueprint_model.refresh()
        elif out_of_contact:  # its rows say how long ago the robot was heard
            self.synced_model.refresh()
        self.policy_in_force = status.lost_link if status is not None else None
        pending, in_force = self.pending_policy, self.policy_in_force
        if pending is not None and in_force is not None and pending.taken_as(in_force.policy):
            self.pending_policy = None  # the robot took it
        if self.pending_policy is not None:
            self.status_label.setText(
                f"{self.status_label.text()}<br><span style='color:#8a5a00'>new policy waiting "
                f"for contact: {escape(self.pending_policy.describe())}</span>"
            )
        show_coverage_warning(self.warning_label, status)
        hold = lost_link_hold(self._view, self.agent)
        if (hold is None) != (self.hold_notice.hold is None):
            self.synced_model.refresh()  # its paused row says that it holds (or no more)
        self.hold_notice.show_hold(hold)
        wait = barrier_wait(self._view, self.agent)
        self.wait_label.setText(wait)
        self.wait_label.setVisible(bool(wait))
        self.synced_caption.setText(on_robot_caption(status))

    def set_skills(self, names: Sequence[str]) -> None:
        """The skills the Add menu offers (the robot's skills)."""
        self.add_menu.clear()
        self.skill_names = sorted(names)
        for name in self.skill_names:
            self.add_menu.addAction(name)

    def set_legal(self, legal: set[RobotAction], read_only: bool) -> None:
        """Enable the buttons whose action can work now."""
        for action, button in self.buttons.items():
            button.setEnabled(not read_only and action in legal)
        self.add_button.setEnabled(not read_only and not self.add_menu.isEmpty())
        self.policy_button.setEnabled(not read_only and bool(self.skill_names))
        self.hold_notice.resume_button.setEnabled(not read_only)
        self.blueprint_table.setDragEnabled(not read_only)  # no reordering a replay

    def _on_hold_notice_resume_requested(self) -> None:
        self.robot_action.emit(self.agent, RobotAction.RESUME)

    def _on_add_menu_triggered(self, action: object) -> None:
        self.add_requested.emit(self.agent, action.text())  # type: ignore[attr-defined]

    def _on_policy_button_clicked(self) -> None:
        in_force, default = self.policy_in_force, self.default_policy
        reported = in_force is not None
        if in_force is None and default is not None:  # not reported yet: the server sends this
            in_force = PolicyInForce(default, library_default=True)
        args = (self.agent, self.skill_names, self, in_force, self.pending_policy, reported)
        policy = self.ask_policy(*args)
        if policy is not None:
            self.pending_policy = policy  # shown as waiting until the robot reports it
            self.policy_chosen.emit(self.agent, policy)

    def policy_refused(self) -> None:
        """The server refused the policy chosen here: nothing waits for the robot."""
        self.pending_policy = None


def on_robot_caption(status: AgentStatus | None) -> str:
    """The caption over the robot's section: marked last known while it is not heard."""
    if status is None or status.link is LinkStatus.UP:
        return ON_ROBOT
    if status.link is LinkStatus.UNKNOWN or status.last_heard < 0:
        return "<i>On the robot</i> <span style='color:#a00000'>(last known, not heard yet)</span>"
    age = duration_text(status.last_heard)
    return f"<i>On the robot</i> <span style='color:#a00000'>(last known, {age} ago)</span>"


def _row_edit(delta: SkillDelta, synced_end: int, synced: TaskModel, blueprint: TaskModel) -> bool:
    """Make ``delta`` as a row edit if it keeps the sections' bounds; False if it cannot."""
    if isinstance(delta, SkillChanged):
        if (delta.old.status is SkillStatus.IDLE) != (delta.new.status is SkillStatus.IDLE):
            return False  # the skill changes section
        if delta.index < synced_end:
            return synced.replace_row(delta.index, delta.new)
        return blueprint.replace_row(delta.index - synced_end, delta.new)
    if isinstance(delta, (SkillAdded, SkillRemoved)):
        if delta.index < synced_end or delta.skill.status is not SkillStatus.IDLE:
            return False
        if isinstance(delta, SkillAdded):
            return blueprint.insert_row(delta.index - synced_end, delta.skill)
        return blueprint.remove_row(delta.index - synced_end, delta.skill.id)
    return False  # moves: compare rows
