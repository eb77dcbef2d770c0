"""The command GUI's only contact with ROS: mirror updates in, service calls out, as Qt signals.

:class:`RosBridge` follows the mission with a
:class:`~rosmc_server.ros.client.MissionFollower` and runs every request through an
:class:`~rosmc_server.ros.client.AsyncMissionClient`; nothing here waits on the GUI thread.
Mirror listeners run on ROS threads with the mirror's lock held: they only copy what
changed into a :class:`~.view_state.ViewUpdate` and queue it; the GUI thread is woken
once per batch and takes every queued update in one slot (:attr:`RosBridge.updated`
carries a tuple of them), so a burst of events costs one pass of the window's
per-batch work, not one per event.

ROS interface (each name behind ``prefix``, e.g. ``/replay``):
    Subscribes ``/rosmc/mission_events`` (rosmc/MissionEvent) and ``/rosmc/agent_states``
    (rosmc/AgentStates) through the follower, ``/rosmc/selection`` (rosmc/Selection) and
    ``/rosmc/sim/science`` (rosmc/ScienceState, through a ScienceWatch) and
    ``/rosmc/site_in_force`` (rosmc/SiteInForce, through a SiteWatch).
    Publishes ``/rosmc/selection`` (rosmc/Selection, latched; live server only).
    Calls the operator services ``/rosmc/<operation>`` (rosmc_server.interface.SERVICES).
"""

from __future__ import annotations

import logging
import threading
from collections import deque
from typing import Any

import rosmc.msg as wire
import rospy
from python_qt_binding.QtCore import QObject, Signal

from rosmc_server import interface
from rosmc_server.core import Library, RosmcError
from rosmc_server.core.live.updates import MirrorUpdate
from rosmc_server.ros.client import (
    AsyncMissionClient,
    MissionClient,
    MissionFollower,
    Outcome,
    RevisionConflict,
    ScienceWatch,
    ServerUnavailable,
    SiteWatch,
)

from .core.pending_backend import follows_replay
from .core.requests import Answer, Request
from .core.view_state import ViewUpdate, view_update

_log = logging.getLogger(__name__)


class RosBridge(QObject):  # type: ignore[misc]
    """Feeds a command widget from ROS and runs its requests; create it on the GUI thread.

    The process must be a ROS node already (``rosmc_server.ros.client.init_node``).

    Args:
        prefix: Namespace before every name ("" for the live server; a replay's prefix
            makes the bridge read-only).
        timeout: Seconds a service call waits for the server.
    """

    updated = Signal(object)  # tuple[ViewUpdate, ...], in revision order
    _wake = Signal()  # ROS thread -> GUI thread: updates are queued
    library_ready = Signal(object)  # Library
    answered = Signal(object)  # Answer
    connection_changed = Signal(bool)
    server_restarted = Signal(int)  # the revision a new server process resumed at
    journal_alert = Signal(str)  # the server's journal alert ("" once it clears)
    selection_received = Signal(list, list)  # skill ids, marker names
    science_received = Signal(object)  # rosmc_server.core.views.science.Science
    site_received = Signal(object)  # rosmc_server.core.world.site_source.SiteInForce | None

    def __init__(self, prefix: str = "", timeout: float = 5.0) -> None:
        super().__init__()
        self.prefix = prefix
        self.read_only = follows_replay(prefix)
        self._follower = MissionFollower(
            prefix,
            timeout=timeout,
            on_connection=self._on_connection,
            on_restart=self.server_restarted.emit,
            on_journal_alert=self.journal_alert.emit,
        )
        self._have_library = False
        self._queue: deque[ViewUpdate] = deque()
        self._queue_lock = threading.Lock()
        self._wake.connect(self._on_wake)  # queued: emitted on ROS threads
        self._client = AsyncMissionClient(MissionClient(timeout, prefix), "rosmc-command")
        self._unsubscribe = self._follower.mirror.subscribe(self._on_mirror_update)
        self._name = rospy.get_name()
        topic = interface.prefixed(interface.SELECTION_TOPIC, prefix)
        self._selection_pub = (
            None
            if self.read_only
            else rospy.Publisher(topic, wire.Selection, queue_size=1, latch=True)
        )
        self._selection_sub = rospy.Subscriber(topic, wire.Selection, self._on_selection)
        self._science = ScienceWatch(prefix, self.science_received.emit)
        self._site = SiteWatch(prefix, self.site_received.emit)

    @property
    def mirror_revision(self) -> int | None:
        """The mirror's revision (for tests and benchmarks)."""
        return self._follower.mirror.revision

    def start(self) -> None:
        """Fetch the mission and the library; follow events from now on."""
        self._follower.start()
        self._follower.library(self._on_library)

    def close(self) -> None:
        """Stop following and calling (pending calls are dropped)."""
        self._unsubscribe()
        self._selection_sub.unregister()
        self._science.close()
        self._site.close()
        if self._selection_pub is not None:
            self._selection_pub.unregister()
        self._follower.close()
        self._client.close()

    # -- Backend ------------------------------------------------------------------------------
    def request(self, request: Request) -> None:
        """Run ``request`` on the worker; :attr:`answered` carries the outcome."""
        self._client.submit(
            request, lambda outcome: self._on_outcome(request, outcome), seen=request.seen
        )

    def refresh(self) -> None:
        """Fetch a new snapshot."""
        self._follower.refresh()

    def publish_selection(self, skill_ids: list[str], marker_names: list[str]) -> None:
        """Publish what is selected here, for rviz."""
        if self._selection_pub is None:
            return
        self._selection_pub.publish(
            wire.Selection(
                source=self._name,
                stamp=rospy.Time.now(),
                skill_ids=list(skill_ids),
                marker_names=list(marker_names),
            )
        )

    # -- callbacks (ROS and worker threads: only emit) ---------------------------------------------
    def _on_mirror_update(self, update: MirrorUpdate) -> None:
        converted = view_update(update, self._follower.mirror.state)
        if converted.reset:  # a new server may count from a lower revision: forget ours
            revision = converted.revision
            self._client.submit(lambda client: client.forget_newer_than(revision))
        with self._queue_lock:
            wake = not self._queue
            self._queue.append(converted)
        if wake:
            self._wake.emit()

    def _on_wake(self) -> None:
        """GUI thread: hand every queued update over at once."""
        with self._queue_lock:
            batch = tuple(self._queue)
            self._queue.clear()
        if batch:
            self.updated.emit(batch)

    def _on_library(self, outcome: Outcome[Library]) -> None:
        if outcome.value is not None:
            self._have_library = True
            self.library_ready.emit(outcome.value)
        else:
            # The server may not be up yet: _on_connection asks again when it appears.
            _log.info("cannot fetch the skill library yet (%s)", outcome.error)

    def _on_connection(self, connected: bool) -> None:
        if connected and not self._have_library:
            self._follower.library(self._on_library)
        self.connection_changed.emit(connected)

    def _on_outcome(self, request: Request, outcome: Outcome[Any]) -> None:
        error = outcome.error
        if error is None:
            self.answered.emit(Answer(request, value=outcome.value))
            return
        conflict = isinstance(error, RevisionConflict)
        if conflict:
            self._follower.refresh()
        self.answered.emit(
            Answer(
                request,
                error=_sentence(error),
                conflict=conflict,
                unreachable=isinstance(error, ServerUnavailable),
            )
        )

    def _on_selection(self, msg: wire.Selection) -> None:
        if msg.source != self._name:
            self.selection_received.emit(list(msg.skill_ids), list(msg.marker_names))


def _sentence(error: RosmcError) -> str:
    text = str(error).strip().rstrip(".")
    return text or type(error).__name__
