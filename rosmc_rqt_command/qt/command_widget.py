"""The command GUI: task, parameter and control panels, warnings, messages and menus.

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

from python_qt_binding.QtCore import QPoint
from python_qt_binding.QtWidgets import QMenu, QWidget

from rosmc_server.core import AgentStatus, Library, LostLinkPolicy
from rosmc_server.core.live.edit_history import EditKind

from ..core.dispatch import Dispatcher
from ..core.legality import Action, RobotAction
from ..core.mission_view import MissionView
from ..core.phrasing import answer_detail, answer_message
from ..core.place_choices import surroundings
from ..core.requests import Answer, Backend, Request, ask
from ..core.view_state import ViewUpdate
from .actions import CommandActions
from .control_panel import ControlPanel
from .duplicate_action import DuplicateAction
from .enabling import Enabling
from .file_menu import FileController
from .message_area import MessageArea
from .parameter_panel import ParameterPanel
from .place_requests import PlaceRequests
from .repaints import Repaints
from .section_table import SectionTable
from .task_widget import TaskWidget
from .team_bar import TeamBar
from .team_dialog import ask_send_anyway, ask_team_send
from .undo_history import UndoHistory
from .window_layout import Panels, lay_out


class CommandWidget(QWidget):  # type: ignore[misc]
    """The operator's command window: a composition of small parts.

    The panels (tasks, team bar, parameters, control, messages), the file menu's
    controller, the undo history, the :class:`~..core.dispatch.Dispatcher` (actions to
    requests), :class:`~.enabling.Enabling` (what is enabled) and
    :class:`~.repaints.Repaints` (timed repaints and warnings); :func:`~.window_layout.lay_out`
    places them. The widget itself only wires them and takes what the backend reports.
    """

    def __init__(self, backend: Backend, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.setObjectName("rosmc_command")
        self.setWindowTitle("ROSMC command")
        self.backend = backend
        self.view = view = MissionView()
        self.actions_ = CommandActions(self)
        self.tasks = TaskWidget(view)
        self.parameters = ParameterPanel(view)
        self.control = ControlPanel(self.actions_)
        self.messages = MessageArea()
        self.files = FileController(self, self.actions_, view, self.messages, self.send)
        self.history = UndoHistory(self, view, self.send)
        self.team = TeamBar(self.tasks, view)
        self.enabling = Enabling(view, self.actions_, self.tasks, self.history)
        self.repaints = Repaints(view, self.messages, self._show_statuses)
        self.dispatcher = Dispatcher(
            view, self.send, self._confirm, self.enabling.legal_for_all, self._confirm_team
        )
        panels = Panels(
            self.actions_,
            self.history,
            self.tasks,
            self.team,
            self.parameters,
            self.control,
            self.messages,
        )
        layout = lay_out(self, panels)
        self.menu_bar, self.banner, self.splitter = layout.menu_bar, layout.banner, layout.splitter
        self.science, self.site, self.legend = layout.science, layout.site, layout.legend
        self._select_when_seen: list[str] = []
        self.places = PlaceRequests(
            view,
            self.send,
            lambda: surroundings(view, self.science.science, self.site.source),
            self._select_soon,
        )
        self.places.connect_rows(self.parameters.places)
        self.duplicate = DuplicateAction(
            self,
            view,
            lambda: self.tasks.selected_ids,
            self.send,
            self._select_soon,
            self.messages.say,
            lambda: self.backend.read_only,
            self.history.join,
        )
        self._journal_alerting = False  # the server said its journal has a problem
        self.connected = False
        self._connect()
        self.banner.setText("Waiting for the mission server…")
        self.set_backend(backend)

    def _connect(self) -> None:
        self.tasks.selection_changed.connect(self._on_tasks_selection_changed)
        self.tasks.context_menu_requested.connect(self._on_tasks_context_menu_requested)
        self.tasks.robot_action.connect(self._on_tasks_robot_action)
        self.messages.resume_requested.connect(self._on_messages_resume_requested)
        self.tasks.add_requested.connect(self._on_tasks_add_requested)
        self.tasks.policy_chosen.connect(self._on_tasks_policy_chosen)
        self.tasks.reorder_requested.connect(self._on_tasks_reorder_requested)
        self.tasks.columns_added.connect(self._on_tasks_columns_added)
        self.parameters.edit_requested.connect(self._on_parameters_edit_requested)
        self.parameters.rename_marker_requested.connect(self._on_parameters_rename_requested)
        self.parameters.problem.connect(lambda text: self.messages.say(text, "warning"))
        self.parameters.places.said.connect(lambda text: self.messages.say(text, "info"))
        for kind, action in self.actions_.skill.items():
            action.triggered.connect(lambda _=False, k=kind: self.do(k))
        for robot_action, action in self.actions_.all_robots.items():
            action.triggered.connect(lambda _=False, r=robot_action: self.do_robot(None, r))
        self.actions_.refresh.triggered.connect(self._on_refresh_triggered)
        self.actions_.clear_selection.triggered.connect(self.tasks.clear_selection)

    # -- from the backend ---------------------------------------------------------------------
    def on_update(self, update: ViewUpdate) -> None:
        """Show one mission update (GUI thread, in revision order)."""
        self.on_updates((update,))

    def on_updates(self, updates: Sequence[ViewUpdate]) -> None:
        """Show several mission updates at once (GUI thread, in revision order).

        Rows change update by update (only those an update touched); what depends on the
        whole picture (buttons, parameter panel, warnings) is worked out once per batch.
        Robot reports are only collected here and shown by a timer (see :mod:`.repaints`).
        """
        agents: set[str] = set()
        changed: set[str] = set()
        first = reset = refresh_parameters = False
        for update in updates:
            first = first or (not self.view.loaded and update.reset)
            reset = reset or update.reset
            self.view.apply(update)
            self.tasks.apply(update)
            agents.update(update.touched)
            changed |= update.changed_ids
            refresh_parameters = refresh_parameters or bool(
                update.touched or update.markers is not None or update.barriers is not None
            )
            self.repaints.note_statuses(update.statuses)
        if refresh_parameters:
            self.parameters.refresh(force=reset or any(u.markers is not None for u in updates))
        if self._select_when_seen and all(self.view.skill(i) for i in self._select_when_seen):
            self.tasks.select_ids(self._select_when_seen)
            self._select_when_seen = []
        self.repaints.checker.note(None if reset else changed)
        self.enabling.update(None if reset else agents)
        self.duplicate.update()
        self.files.on_mission_shown()
        if first:
            self.files.mark_saved()
            self.messages.say("Mission shown.", "ok", f"mission revision {self.view.revision}")
        if reset:
            self.banner.hide()
        self.team.refresh()
        if agents or reset:
            self.repaints.warn_soon()

    def on_library(self, library: Library) -> None:
        """The skill library arrived: offer each robot's skills."""
        self.view.library = library
        self.tasks.set_library(library)
        self.parameters.refresh(force=True)
        self.repaints.checker.note(None)
        self.enabling.update()
        self.repaints.warn_soon()

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

    def on_server_restarted(self, revision: int) -> None:
        """A new mission server process took over (a restart); say from which revision."""
        self.messages.say(
            "The mission server restarted with the mission as it last recorded it; robot "
            "states are shown again as it hears the robots.",
            "warning",
            f"restarted from mission revision {revision}",
        )

    def on_journal_alert(self, alert: str) -> None:
        """The server's journal alert changed: a full disk refuses changes, or history lost.

        Said when it begins and when it clears (its byte count may change in between).
        """
        alerting, self._journal_alerting = self._journal_alerting, bool(alert)
        if alert and not alerting:
            self.messages.say(f"Journal: {alert}.", "error")
        elif alerting and not alert:
            self.messages.say("The journal's alert cleared: changes are recorded again.", "info")

    def on_answer(self, answer: Answer) -> None:
        """Say how a request ended."""
        hint = self.history.note(answer) if answer.ok else ""  # "Ctrl+Z undoes it"
        text, severity = answer_message(answer, hint)
        self.messages.say(text, severity, answer_detail(answer))
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
        if ids != self.tasks.selected_ids:
            self.tasks.select_ids(ids)

    def set_backend(self, backend: Backend) -> None:
        """Talk to ``backend`` from now on (a replay's, or the live one again)."""
        self.backend = backend
        self.view.statuses = {}  # the robots as the new backend reports them
        self.parameters.set_read_only(backend.read_only)
        self.enabling.read_only = backend.read_only
        self.messages.set_read_only(backend.read_only)
        self.enabling.update()
        self.duplicate.update()

    # -- sending ------------------------------------------------------------------------------
    def send(self, request: Request) -> None:
        """Hand a request to the backend (refused at once when following read-only)."""
        if self.backend.read_only:
            self.messages.say(
                "This window follows a replay; it cannot change the mission.", "warning"
            )
            return
        self.backend.request(request)

    def do(self, kind: Action) -> None:
        """Run a skill action on the selection (if it is legal now)."""
        if not self.backend.read_only:
            self.dispatcher.skill_action(kind, self.view.skills(self.tasks.selected_ids))

    def do_robot(self, agent: str | None, kind: RobotAction) -> None:
        """Run a robot action on ``agent`` (None: every robot), if it is legal now."""
        if not self.backend.read_only:
            self.dispatcher.robot_action(agent, kind)

    def _confirm(self, warnings: list[str]) -> bool:
        for warning in warnings:
            self.messages.say(warning, "warning")
        return ask_send_anyway(self, warnings)

    def _confirm_team(self, text: str, warnings: list[str]) -> bool:
        return ask_team_send(self, text, warnings)

    # -- slots ----------------------------------------------------------------------------------
    def _on_tasks_selection_changed(self, ids: list[str]) -> None:
        self.parameters.show_selection(ids)
        self.enabling.update()
        self.duplicate.update()
        selected = self.view.skills(ids)
        self.backend.publish_selection(ids, self.view.bound_markers(selected))

    def _on_tasks_context_menu_requested(self, table: SectionTable, pos: QPoint) -> None:
        self.context_menu(table).exec_(pos)

    def context_menu(self, table: SectionTable) -> QMenu:
        """The right-click menu of a table: what can be done to the selection there."""
        menu = QMenu(self)
        for action in self.actions_.skill.values():
            if action.isEnabled():
                menu.addAction(action)
        if self.duplicate.action.isEnabled():
            menu.addAction(self.duplicate.action)
        agent = table.section.agent
        column = self.tasks.columns.get(agent)
        if table.section.blueprint and column is not None and column.add_button.isEnabled():
            menu.addSeparator()
            menu.addMenu(column.add_menu).setText(f"Add skill to {agent}")
        if menu.isEmpty():
            menu.addAction("Nothing can be done to this selection").setEnabled(False)
        return menu

    def _on_tasks_robot_action(self, agent: str, kind: RobotAction) -> None:
        self.do_robot(agent, kind)

    def _on_messages_resume_requested(self, agent: str) -> None:
        self.do_robot(agent, RobotAction.RESUME)

    def _on_tasks_add_requested(self, agent: str, skill: str) -> None:
        self.places.add_skill(agent, skill)

    def _select_soon(self, skill_ids: list[str]) -> None:
        """Select ``skill_ids`` now, or as soon as the update that shows them arrives."""
        self._select_when_seen = list(skill_ids)
        if all(self.view.skill(i) is not None for i in skill_ids):
            self.tasks.select_ids(self._select_when_seen)
            self._select_when_seen = []

    def _on_tasks_policy_chosen(self, agent: str, policy: LostLinkPolicy) -> None:
        def forget_if_refused(answer: Answer) -> None:
            column = self.tasks.columns.get(agent)
            if not answer.ok and column is not None:
                column.policy_refused()

        what = f"set {agent}'s policy ({policy.describe()})"
        call = ask(lambda c: c.set_lost_link_policy, what, self.view.revision, forget_if_refused)
        self.send(call(agent, policy))

    def _on_tasks_reorder_requested(self, agent: str, order: list[str]) -> None:
        what = f"reorder {agent}'s task"
        self.dispatcher.call(lambda c: c.reorder_skills, what, EditKind.REORDER_SKILLS)(
            agent, order
        )

    def _on_tasks_columns_added(self, agents: list[str]) -> None:
        self.team.refresh()
        self.enabling.update(agents)

    def _on_parameters_edit_requested(self, skill_id: str, fields: dict[str, Any]) -> None:
        skill = self.view.skill(skill_id)
        name = f"'{skill.label or skill.skill}'" if skill is not None else skill_id
        changed = ", ".join(fields.get("params", {}) or fields.get("bindings", {}) or fields)
        revert = self.parameters.reverter(skill_id)  # a refused value leaves the field
        what = f"change {changed} of {name}"
        call = ask(lambda c: c.edit_skill, what, self.view.revision, revert, EditKind.EDIT_SKILL)
        self.send(call(skill_id, **fields))

    def _on_parameters_rename_requested(self, old: str, new: str) -> None:
        what = f"rename marker {old} to {new}"
        self.dispatcher.call(lambda c: c.rename_task_marker, what, EditKind.RENAME_MARKER)(old, new)

    def _on_refresh_triggered(self) -> None:
        self.backend.refresh()
        self.messages.say("Fetching the mission again.", "info")

    def _show_statuses(self, statuses: list[AgentStatus]) -> None:
        """The robots' latest reports, collected by the status timer: headers and buttons."""
        self.tasks.show_statuses(statuses)
        self.team.refresh()
        self.enabling.update(status.agent for status in statuses)
