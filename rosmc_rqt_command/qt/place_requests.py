"""What the place rows and the Add menus ask of the mission server, sent as requests.

* A skill added from a robot's Add menu takes its default places
  (:func:`~..core.place_choices.new_skill_places`) in the same ``add_skill``.
* ``New marker here…``: ``add_task_marker`` at the parameter's value, then, once it is
  accepted, ``edit_skill`` binding the parameter to it (two changes: undo takes back the
  binding, then the marker).
* ``Drive there first``: one ``add_skill`` of the robot's move, just before the skill.
"""

from __future__ import annotations

from collections.abc import Callable

from python_qt_binding.QtCore import QObject

from rosmc_server.core import TaskMarker
from rosmc_server.core.live.edit_history import EditKind
from rosmc_server.core.skills.params import value_to_data
from rosmc_server.core.views.drive_first import DriveFirst
from rosmc_server.core.views.places import Surroundings

from ..core.mission_view import MissionView
from ..core.place_choices import new_skill_places
from ..core.requests import Answer, Request, ask
from .place_rows import PlaceRows

# The edits this module's requests make (undo takes each back).
ADD, EDIT, NEW_MARKER = EditKind.ADD_SKILL, EditKind.EDIT_SKILL, EditKind.ADD_MARKER


class PlaceRequests(QObject):  # type: ignore[misc]
    """Turns place choices into requests.

    Args:
        view: The mission as shown (for the revision and the defaults).
        send: Hands a request to the backend.
        around: What is known around the mission now.
        select: Selects skills by id once they are shown.
    """

    def __init__(
        self,
        view: MissionView,
        send: Callable[[Request], None],
        around: Callable[[], Surroundings],
        select: Callable[[list[str]], None],
    ) -> None:
        super().__init__()
        self._view = view
        self._send = send
        self._around = around
        self._select = select

    def connect_rows(self, rows: PlaceRows) -> None:
        """Send what ``rows`` ask for."""
        rows.around = self._around
        rows.marker_requested.connect(self._on_rows_marker_requested)
        rows.drive_requested.connect(self._on_rows_drive_requested)

    def add_skill(self, agent: str, skill: str) -> None:
        """Append ``skill`` to ``agent``'s blueprint at its default places; select it."""
        params, bindings = new_skill_places(self._view, self._around(), agent, skill)
        what = f"add {skill} to {agent}"
        call = ask(lambda c: c.add_skill, what, self._view.revision, self._chosen, ADD)
        self._send(call(agent, skill, params, bindings=bindings))

    def _chosen(self, answer: Answer) -> None:
        if answer.ok:
            self._select([answer.value.skill_id])

    def _on_rows_marker_requested(self, skill_id: str, param: str, marker: TaskMarker) -> None:
        def bind(answer: Answer) -> None:
            if answer.ok:
                what = f"bind {param} to marker {answer.value.name}"
                edit = ask(lambda c: c.edit_skill, what, answer.value.revision, kind=EDIT)
                self._send(edit(skill_id, bindings={param: answer.value.name}))

        what = f"new {marker.type.name.lower()} marker for {param}"
        made = ask(lambda c: c.add_task_marker, what, self._view.revision, bind, NEW_MARKER)
        self._send(made(marker))

    def _on_rows_drive_requested(self, offer: DriveFirst) -> None:
        params = {name: value_to_data(value) for name, value in offer.params.items()}
        call = ask(lambda c: c.add_skill, f"add {offer.words}", self._view.revision, kind=ADD)
        self._send(
            call(offer.agent, offer.skill, params, bindings=offer.bindings, index=offer.index)
        )
