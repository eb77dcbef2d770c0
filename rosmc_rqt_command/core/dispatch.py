"""What each operator action asks of the mission server, as :class:`~.requests.Request` values.

:class:`Dispatcher` turns a skill action on the selection, or a robot action, into the
request(s) that carry it out, in words the message area can repeat ("send alpha's task
up to 'go to A'"). It checks legality first (a shortcut may fire while its button is
disabled) and asks before sending a barrier member whose partners stay behind.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, ParamSpec

from rosmc_server.core import SkillInstance
from rosmc_server.core.live.edit_history import EditKind
from rosmc_server.core.model.control import ControlCommand

from . import alerts
from .legality import Action, RobotAction, legal_actions, legal_robot_actions, selection_agent
from .mission_view import MissionView
from .requests import Request, ask
from .team_send import plan_team_send, team_question, up_to_selection, whole_team

if TYPE_CHECKING:  # for the type checker only
    from rosmc_server.ros.client import MissionClient

P = ParamSpec("P")
CONTROLS = {
    RobotAction.START: ControlCommand.START,
    RobotAction.PAUSE: ControlCommand.PAUSE,
    RobotAction.RESUME: ControlCommand.RESUME,
    RobotAction.STOP: ControlCommand.STOP,
}
Confirm = Callable[[list[str]], bool]  # warnings -> send anyway?
ConfirmTeam = Callable[[str, list[str]], bool]  # what goes, warnings -> send?


class Dispatcher:
    """Builds and sends the requests of the operator's actions.

    Args:
        view: The mission as shown.
        send: Hands a request to the backend.
        confirm: Asked with the warnings before a barrier member goes alone.
        legal_for_all: The robot actions legal on at least one robot now.
        confirm_team: Asked once, with what goes and every warning, before a team send.
    """

    def __init__(
        self,
        view: MissionView,
        send: Callable[[Request], None],
        confirm: Confirm,
        legal_for_all: Callable[[], set[RobotAction]],
        confirm_team: ConfirmTeam,
    ) -> None:
        self._view = view
        self._send = send
        self.confirm = confirm  # tests answer the question through this
        self.confirm_team = confirm_team
        self._legal_for_all = legal_for_all

    def call(
        self,
        pick: Callable[[MissionClient], Callable[P, object]],
        what: str,
        kind: EditKind | None = None,
    ) -> Callable[P, None]:
        """A sender of one call of the client method ``pick`` chooses, against the revision
        shown: ``call(lambda c: c.retry_skill, "retry 'go'")(skill_id)``; ``kind``: the
        edit it makes (undo can take it back)."""
        make = ask(pick, what, self._view.revision, kind=kind)

        def send(*args: P.args, **kwargs: P.kwargs) -> None:
            self._send(make(*args, **kwargs))

        return send

    def skill_action(self, kind: Action, selected: Sequence[SkillInstance]) -> None:
        """Run ``kind`` on the selected skills (nothing if it is not legal for them)."""
        if not selected or kind not in legal_actions(self._view, selected):
            return
        names = ", ".join(f"'{s.label or s.skill}'" for s in selected)
        handlers = {
            Action.DELETE: self._delete,
            Action.MOVE_UP: self._move,
            Action.MOVE_DOWN: self._move,
            Action.SYNC: self._sync,
            Action.UNSYNC: self._unsync,
            Action.RETRY: self._resolve,
            Action.SKIP: self._resolve,
            Action.BARRIER: self._barrier,
            Action.DELETE_BARRIER: self._delete_barrier,
        }
        handlers[kind](kind, selected, names)

    def _delete(self, _: Action, selected: Sequence[SkillInstance], names: str) -> None:
        self.call(lambda c: c.delete_skills, f"delete {names}", EditKind.DELETE_SKILLS)(
            [s.id for s in selected]
        )

    def _move(self, kind: Action, selected: Sequence[SkillInstance], names: str) -> None:
        agent = selected[0].agent
        order = moved([s.id for s in self._view.view(agent).editable], selected, kind)
        self.call(lambda c: c.reorder_skills, f"move {names}", EditKind.REORDER_SKILLS)(
            agent, order
        )

    def _sync(self, _: Action, selected: Sequence[SkillInstance], names: str) -> None:
        view = self._view
        if selection_agent(selected) is None:
            self.send_team(up_to_selection(view, list(selected)))
            return
        agent = selected[0].agent
        last = max(view.position(s) for s in selected)
        sending = [s for s in view.view(agent).editable if view.position(s) <= last]
        if self._barriers_ok(sending):
            what = f"send {agent}'s task up to {names}"
            self.call(lambda c: c.synchronize, what)(agent, sending[-1].id)

    def _unsync(self, _: Action, selected: Sequence[SkillInstance], names: str) -> None:
        start = min(selected, key=self._view.position)
        what = f"take back {start.agent}'s skills from '{start.label or start.skill}'"
        self.call(lambda c: c.unsynchronize, what)(start.agent, start.id)

    def _resolve(self, kind: Action, selected: Sequence[SkillInstance], names: str) -> None:
        if kind is Action.RETRY:
            self.call(lambda c: c.retry_skill, f"retry {names}")(selected[0].id)
        else:
            self.call(lambda c: c.skip_skill, f"skip {names}")(selected[0].id)

    def _barrier(self, _: Action, selected: Sequence[SkillInstance], names: str) -> None:
        self.call(lambda c: c.add_barrier, f"start {names} together", EditKind.ADD_BARRIER)(
            [s.id for s in selected]
        )

    def _delete_barrier(self, _: Action, selected: Sequence[SkillInstance], names: str) -> None:
        barriers = {b.id for s in selected if (b := self._view.barrier_of(s.id)) is not None}
        for barrier_id in sorted(barriers):
            self.call(
                lambda c: c.delete_barrier, f"remove barrier of {names}", EditKind.DELETE_BARRIER
            )(barrier_id)

    def robot_action(self, agent: str | None, kind: RobotAction) -> None:
        """Run ``kind`` on ``agent`` (None: every robot), if it is legal now."""
        legal = self._legal_for_all() if agent is None else legal_robot_actions(self._view, agent)
        if kind not in legal:
            return
        who = "every robot" if agent is None else agent
        if kind is RobotAction.SYNC_ALL and agent is None:
            self.send_team(whole_team(self._view))
        elif kind is RobotAction.SYNC_ALL and agent is not None:
            self._send_whole_task(agent)
        elif kind is RobotAction.UNSYNC_ALL and agent is not None:
            self.call(lambda c: c.unsynchronize, f"take back {agent}'s task")(agent, None)
        elif kind in CONTROLS:
            self.call(lambda c: c.control, f"{kind.value} {who}")(CONTROLS[kind], agent)

    def send_team(self, uploads: dict[str, str | None]) -> None:
        """Send several robots' tasks in one change, after one question listing every warning."""
        send = plan_team_send(self._view, uploads)
        if send is None:
            return
        text, warnings = team_question(self._view, send)
        if self.confirm_team(text, warnings):
            robots = ", ".join(send.sending)
            what = f"send the tasks of {robots}"
            self.call(lambda c: c.synchronize_team, what)(dict(send.uploads))

    def _send_whole_task(self, agent: str) -> None:
        """Send ``agent``'s whole task after one question naming what goes (a button beside
        *Add skill* must never send a task by a slip of the mouse)."""
        send = plan_team_send(self._view, {agent: None})
        if send is None:
            return
        text, warnings = team_question(self._view, send)
        if self.confirm_team(text, warnings):
            self.call(lambda c: c.synchronize, f"send {agent}'s whole task")(agent, None)

    def _barriers_ok(self, sending: Sequence[SkillInstance]) -> bool:
        warnings = alerts.barrier_warnings(self._view, sending)
        return not warnings or self.confirm(warnings)


def moved(order: list[str], selected: Sequence[SkillInstance], kind: Action) -> list[str]:
    """``order`` with the selected skills one place earlier (MOVE_UP) or later."""
    order = list(order)
    ids = {s.id for s in selected}
    up = kind is Action.MOVE_UP
    step = -1 if up else 1
    positions = sorted((order.index(i) for i in ids if i in order), reverse=not up)
    for position in positions:
        target = position + step
        if 0 <= target < len(order) and order[target] not in ids:
            order[position], order[target] = order[target], order[position]
    return order
