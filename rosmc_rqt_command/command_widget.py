"""The command GUI: schedule, parameter and control panels, warnings, messages and menus.

A plain Qt widget (the rqt plugin and the standalone window both host it). It knows the
outside world only as a :class:`~.requests.Backend`: it receives mission updates, the
library, answers and the connection state through its ``on_*`` slots and sends
:class:`~.requests.Request` values. Buttons are enabled only when their action can work
for the selection (:mod:`.legality`); the server decides in the end and every answer is
shown as a sentence.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from python_qt_binding.QtCore import QPoint, Qt, QTimer
from python_qt_binding.QtWidgets import (
    QLabel,
    QMenu,
    QMenuBar,
    QMessageBox,
    QSplitter,
    QVBoxLayout,
    QWidget,
)

from rosmc_server.core import Library, SkillInstance

from . import alerts
from .actions import CommandActions
from .agent_column import SectionTable
from .control_panel import ControlPanel
from .file_menu import FileController
from .legality import Action, RobotAction, legal_actions, legal_for_all, legal_robot_actions
from .message_area import MessageArea
from .mission_view import MissionView
from .parameter_panel import ParameterPanel
from .requests import Answer, Backend, Request
from .schedule_widget import ScheduleWidget
from .view_state import ViewUpdate

CONTROL_WORDS = {
    RobotAction.START: "START",
    RobotAction.PAUSE: "PAUSE",
    RobotAction.RESUME: "RESUME",
    RobotAction.STOP: "STOP",
}


class CommandWidget(QWidget):  # type: ignore[misc]
    """The operator's command window content."""

    def __init__(self, backend: Backend, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.setObjectName("rosmc_command")
        self.setWindowTitle("ROSMC command")
        self.backend = backend
        self.view = MissionView()
        self.actions_ = CommandActions(self)
        self.schedule = ScheduleWidget(self.view)
        self.parameters = ParameterPanel(self.view)
        self.control = ControlPanel(self.actions_)
        self.messages = MessageArea()
        self.files = FileController(self, self.actions_, self.view, self.messages, self.send)
        self._checker = alerts.ParameterChecker()
        self._select_when_seen: list[str] = []
        self.connected = False
        self._build_layout()
        self._connect()
        self._warn_timer = QTimer(self)
        self._warn_timer.setSingleShot(True)
        self._warn_timer.setInterval(300)
        self._warn_timer.timeout.connect(self._on_warn_timer_timeout)
        self.banner.setText("Waiting for the mission server…")
        self._update_legal()

    # -- layout ---------------------------------------------------------------------------
    def _build_layout(self) -> None:
        self.menu_bar = QMenuBar(self)
        file_menu = self.menu_bar.addMenu("&File")
        for name in ("new", "open", "open_server", None, "save", "save_as", "save_server"):
            if name is None:
                file_menu.addSeparator()
            else:
                file_menu.addAction(self.actions_.file[name])
        mission_menu = self.menu_bar.addMenu("&Mission")
        for action in self.actions_.skill.values():
            mission_menu.addAction(action)
        mission_menu.addSeparator()
        for action in self.actions_.all_robots.values():
            mission_menu.addAction(action)
        mission_menu.addSeparator()
        mission_menu.addAction(self.actions_.refresh)
        mission_menu.addAction(self.actions_.clear_selection)
        self.banner = QLabel()
        self.banner.setObjectName("banner")
        self.banner.setWordWrap(True)
        self.banner.setStyleSheet("QLabel { background:#fde2e1; color:#8a0010; padding:4px; }")
        right = QSplitter(Qt.Vertical)
        right.addWidget(self.parameters)
        right.addWidget(self.control)
        right.addWidget(self.messages)
        right.setStretchFactor(0, 3)
        right.setStretchFactor(2, 1)
        self.splitter = QSplitter(Qt.Horizontal)
        self.splitter.addWidget(self.schedule)
        self.splitter.addWidget(right)
        self.splitter.setStretchFactor(0, 1)
        self.splitter.setStretchFactor(1, 0)
        self.splitter.setSizes([1100, 420])
        right.setMaximumWidth(480)
        layout = QVBoxLayout(self)
        layout.setContentsMargins(2, 2, 2, 2)
        layout.setMenuBar(self.menu_bar)
        layout.addWidget(self.banner)
        layout.addWidget(self.splitter, 1)

    def _connect(self) -> None:
        self.schedule.selection_changed.connect(self._on_schedule_selection_changed)
        self.schedule.context_menu_requested.connect(self._on_schedule_context_menu_requested)
        self.schedule.robot_action.connect(self._on_schedule_robot_action)
        self.schedule.add_requested.connect(self._on_schedule_add_requested)
        self.schedule.policy_chosen.connect(self._on_schedule_policy_chosen)
        self.schedule.reorder_requested.connect(self._on_schedule_reorder_requested)
        self.parameters.edit_requested.connect(self._on_parameters_edit_requested)
        self.parameters.rename_marker_requested.connect(self._on_parameters_rename_requested)
        self.parameters.problem.connect(lambda text: self.messages.say(text, "warning"))
        for kind, action in self.actions_.skill.items():
            action.triggered.connect(lambda _=False, k=kind: self.do(k))
        for robot_action, action in self.actions_.all_robots.items():
            action.triggered.connect(lambda _=False, r=robot_action: self.do_robot(None, r))
        self.actions_.refresh.triggered.connect(self._on_refresh_triggered)
        self.actions_.clear_selection.triggered.connect(self.schedule.clear_selection)

    # -- from the backend ---------------------------------------------------------------------
    def on_update(self, update: ViewUpdate) -> None:
        """Show one mission update (GUI thread, in revision order)."""
        first = not self.view.loaded and update.reset
        self.view.apply(update)
        self.schedule.apply(update)
        if update.agents or update.markers is not None or update.barriers is not None:
            self.parameters.refresh(force=update.markers is not None or update.reset)
        if self._select_when_seen and all(self.view.skill(i) for i in self._select_when_seen):
            self.schedule.select_ids(self._select_when_seen)
            self._select_when_seen = []
        self._update_legal([v.agent for v in update.agents] + [s.agent for s in update.statuses])
        self.files.on_mission_shown()
        if first:
            self.files.mark_saved()
            self.messages.say(f"Mission shown (revision {update.revision}).", "ok")
        if update.reset:
            self.banner.hide()
        if not self._warn_timer.isActive():
            self._warn_timer.start()

    def on_library(self, library: Library) -> None:
        """The skill library arrived: offer each robot's skills."""
        self.view.library = library
        self.schedule.set_library(library)
        self.parameters.refresh(force=True)
        self._update_legal()

    def on_connection(self, connected: bool) -> None:
        """The mission server appeared or went away."""
        self.connected = connected
        if connected:
            self.banner.hide()
            self.messages.say("Connected to the mission server.", "ok")
        else:
            self.banner.setText(
                "The mission server does not answer. You see the last known mission; "
                "changes cannot be sent until it is back."
            )
            self.banner.show()
            self.messages.say("Lost the mission server; waiting for it to come back.", "error")

    def on_answer(self, answer: Answer) -> None:
        """Say how a request ended."""
        what = answer.request.what or answer.request.operation.replace("_", " ")
        if answer.ok:
            revision = getattr(answer.value, "revision", None)
            suffix = f" (revision {revision})" if revision is not None else ""
            self.messages.say(f"Done: {what}{suffix}.", "ok")
        elif answer.conflict:
            self.messages.say(
                f"Could not {what}: someone else changed the mission first ({answer.error}). "
                "The view was refreshed; check it and try again.",
                "error",
            )
        elif answer.unreachable:
            self.messages.say(
                f"Could not {what}: the mission server did not answer ({answer.error}).", "error"
            )
        else:
            self.messages.say(f"Could not {what}: {answer.error}.", "error")
        if answer.request.on_answer is not None:
            answer.request.on_answer(answer)

    def on_remote_selection(self, skill_ids: list[str], marker_names: list[str]) -> None:
        """Another GUI (rviz) selected skills or markers: select their rows."""
        ids = list(skill_ids)
        if not ids:
            for name in marker_names:
                bound = self.view.skills_bound_to(name)
                if bound:
                    ids.append(bound[0].id)
        if ids != self.schedule.selected_ids:
            self.schedule.select_ids(ids)

    # -- sending ------------------------------------------------------------------------------
    def send(self, request: Request) -> None:
        """Hand a request to the backend (refused at once when following read-only)."""
        if self.backend.read_only:
            self.messages.say(
                "This window follows a replay; it cannot change the mission.", "warning"
            )
            return
        self.backend.request(request)

    def _request(self, operation: str, *args: Any, what: str, **kwargs: Any) -> None:
        self.send(Request(operation, args, kwargs, what, self.view.revision))

    def do(self, kind: Action) -> None:
        """Run a skill action on the selection (if it is legal now)."""
        selected = self.view.skills(self.schedule.selected_ids)
        if kind not in legal_actions(self.view, selected) or self.backend.read_only:
            return
        first = selected[0]
        names = ", ".join(f"'{s.label or s.skill}'" for s in selected)
        if kind is Action.DELETE:
            ids = [s.id for s in selected]
            self._request("delete_skills", ids, what=f"delete {names}")
        elif kind in (Action.MOVE_UP, Action.MOVE_DOWN):
            order = self._moved([s.id for s in selected], first.agent, kind is Action.MOVE_UP)
            self._request("reorder", first.agent, order, what=f"move {names}")
        elif kind is Action.SYNC:
            editable = self.view.view(first.agent).editable
            last = max(self.view.position(s) for s in selected)
            upto = next(s for s in editable if self.view.position(s) == last)
            sending = [s for s in editable if self.view.position(s) <= last]
            if self._confirm_barriers(sending):
                self._request(
                    "synchronize",
                    first.agent,
                    upto.id,
                    what=f"send {first.agent}'s plan up to {names}",
                )
        elif kind is Action.UNSYNC:
            start = min(selected, key=self.view.position)
            self._request(
                "unsynchronize",
                first.agent,
                start.id,
                what=f"take back {first.agent}'s skills from '{start.label or start.skill}'",
            )
        elif kind is Action.RETRY:
            self._request("retry", first.id, what=f"retry {names}")
        elif kind is Action.SKIP:
            self._request("skip", first.id, what=f"skip {names}")
        elif kind is Action.BARRIER:
            self._request("add_barrier", [s.id for s in selected], what=f"start {names} together")
        elif kind is Action.DELETE_BARRIER:
            barriers = {b.id for s in selected if (b := self.view.barrier_of(s.id)) is not None}
            for barrier_id in sorted(barriers):
                self._request("delete_barrier", barrier_id, what=f"remove barrier of {names}")

    def do_robot(self, agent: str | None, kind: RobotAction) -> None:
        """Run a robot action on ``agent`` (None: every robot)."""
        legal = legal_for_all(self.view) if agent is None else legal_robot_actions(self.view, agent)
        if kind not in legal or self.backend.read_only:
            return
        who = "every robot" if agent is None else agent
        if kind is RobotAction.SYNC_ALL and agent is not None:
            if self._confirm_barriers(self.view.view(agent).editable):
                self._request("synchronize", agent, None, what=f"send {agent}'s whole plan")
        elif kind is RobotAction.UNSYNC_ALL and agent is not None:
            self._request("unsynchronize", agent, None, what=f"take back {agent}'s plan")
        elif kind in CONTROL_WORDS:
            word = kind.value
            self._request("control", CONTROL_WORDS[kind], agent, what=f"{word} {who}")

    def _moved(self, ids: list[str], agent: str, up: bool) -> list[str]:
        order = [s.id for s in self.view.view(agent).editable]
        step = -1 if up else 1
        positions = sorted((order.index(i) for i in ids if i in order), reverse=not up)
        for position in positions:
            target = position + step
            if 0 <= target < len(order) and order[target] not in ids:
                order[position], order[target] = order[target], order[position]
        return order

    def _confirm_barriers(self, sending: Sequence[SkillInstance]) -> bool:
        warnings = alerts.barrier_warnings(self.view, sending)
        if not warnings:
            return True
        for warning in warnings:
            self.messages.say(warning, "warning")
        answer = QMessageBox.warning(
            self,
            "A robot would wait for ever",
            "\n".join(warnings) + "\n\nSend anyway?",
            QMessageBox.Yes | QMessageBox.No,
            QMessageBox.No,
        )
        return bool(answer == QMessageBox.Yes)

    # -- slots ----------------------------------------------------------------------------------
    def _on_schedule_selection_changed(self, ids: list[str]) -> None:
        self.parameters.show_selection(ids)
        self._update_legal()
        selected = self.view.skills(ids)
        self.backend.publish_selection(ids, self.view.bound_markers(selected))

    def _on_schedule_context_menu_requested(self, table: SectionTable, pos: QPoint) -> None:
        self.context_menu(table).exec_(pos)

    def context_menu(self, table: SectionTable) -> QMenu:
        """The right-click menu of a table: what can be done to the selection there."""
        menu = QMenu(self)
        for action in self.actions_.skill.values():
            if action.isEnabled():
                menu.addAction(action)
        agent = table.section.agent
        column = self.schedule.columns.get(agent)
        if table.section.blueprint and column is not None and column.add_button.isEnabled():
            menu.addSeparator()
            menu.addMenu(column.add_menu).setText(f"Add skill to {agent}")
        if menu.isEmpty():
            menu.addAction("Nothing can be done to this selection").setEnabled(False)
        return menu

    def _on_schedule_robot_action(self, agent: str, kind: RobotAction) -> None:
        self.do_robot(agent, kind)

    def _on_schedule_add_requested(self, agent: str, skill: str) -> None:
        def select_new(answer: Answer) -> None:
            if answer.ok:
                self._select_when_seen = [answer.value.skill_id]
                if self.view.skill(answer.value.skill_id) is not None:
                    self.schedule.select_ids(self._select_when_seen)
                    self._select_when_seen = []

        self.send(
            Request(
                "add_skill",
                (agent, skill),
                {},
                f"add {skill} to {agent}",
                self.view.revision,
                select_new,
            )
        )

    def _on_schedule_policy_chosen(self, agent: str, policy: str, safe_skill: str) -> None:
        self._request(
            "set_robot_options", agent, policy, safe_skill, what=f"set {agent}'s lost-link policy"
        )

    def _on_schedule_reorder_requested(self, agent: str, order: list[str]) -> None:
        self._request("reorder", agent, order, what=f"reorder {agent}'s plan")

    def _on_parameters_edit_requested(self, skill_id: str, fields: dict[str, Any]) -> None:
        skill = self.view.skill(skill_id)
        name = f"'{skill.label or skill.skill}'" if skill is not None else skill_id
        changed = ", ".join(fields.get("params", {}) or fields.get("bindings", {}) or fields)
        self._request("edit_skill", skill_id, what=f"change {changed} of {name}", **fields)

    def _on_parameters_rename_requested(self, old: str, new: str) -> None:
        self._request("rename_marker", old, new, what=f"rename marker {old} to {new}")

    def _on_refresh_triggered(self) -> None:
        self.backend.refresh()
        self.messages.say("Fetching the mission again.", "info")

    def _on_warn_timer_timeout(self) -> None:
        warnings = [
            *alerts.barrier_warnings(self.view),
            *alerts.coverage_warnings(self.view),
            *self._checker.warnings(self.view),
        ]
        self.messages.show_warnings(warnings)
        if self._checker.incomplete:
            self._warn_timer.start()  # the rest of a big mission next time

    # -- enabling -------------------------------------------------------------------------------
    def _update_legal(self, agents: list[str] | None = None) -> None:
        read_only = self.backend.read_only
        selected = self.view.skills(self.schedule.selected_ids)
        legal = set() if read_only else legal_actions(self.view, selected)
        for kind, action in self.actions_.skill.items():
            action.setEnabled(kind in legal)
        everyone = set() if read_only else legal_for_all(self.view)
        for robot_action, action in self.actions_.all_robots.items():
            action.setEnabled(robot_action in everyone)
        for name, action in self.actions_.file.items():
            action.setEnabled(not read_only or name in ("save_as",))
        for agent, column in self.schedule.columns.items():
            if agents is None or agent in agents:
                column.set_legal(legal_robot_actions(self.view, agent), read_only)
