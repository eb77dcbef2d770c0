"""Undo and Redo from rviz's menus, as mission server calls.

The edits of this rviz are kept in the shared
:class:`~rosmc_server.core.live.edit_history.EditHistory`, by the rule the command GUI
follows too: an undo is made against the revision the operator sees, one at a time; a
conflict or no answer keeps the entry and a refusal drops it, and the log says which and
why. Calls run on the marker node's client worker; nothing here blocks a ROS callback.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from typing import Any

from rosmc_server.core.live.edit_history import EditHistory, Step, failure_of
from rosmc_server.ros.client import AsyncMissionClient, Outcome

_log = logging.getLogger(__name__)


class UndoCalls:
    """Sends this rviz's undos and redos and keeps the history by their answers.

    Args:
        history: This rviz's edits.
        client: The node's client worker.
        seen: The revision the operator sees now (the mirror's).
    """

    def __init__(
        self, history: EditHistory, client: AsyncMissionClient, seen: Callable[[], int | None]
    ) -> None:
        self._history = history
        self._client = client
        self._seen = seen

    def ask(self, redo: bool) -> None:
        """Ask the server to undo this rviz's newest edit (``redo``: its newest undo)."""
        step = self._history.begin(redo=redo, seen=self._seen())
        if step is None:  # nothing to take back, or one step still on its way
            _log.warning("nothing of this rviz's to %s now", "redo" if redo else "undo")
            return
        self._send(step, step.next_revision)

    def _send(self, step: Step, revision: int) -> None:
        future = self._client.submit(
            lambda c: c.undo_edit(revision),
            lambda outcome: self._answered(step, outcome),
            step.base_revision,
        )
        future.add_done_callback(lambda f: f.exception())  # errors reach the callback

    def _answered(self, step: Step, outcome: Outcome[Any]) -> None:
        error = outcome.error
        if error is None:
            following = self._history.accepted(step, int(getattr(outcome.value, "revision", 0)))
            if following is not None:  # several edits in one entry: the next one back
                self._send(step, following)
            else:
                _log.info("%s: done", step.words)
        else:  # kept (a conflict, no answer) or dropped (refused), as the sentence says
            _log.warning("%s", self._history.failed(step, failure_of(error), str(error)))
