"""Keeps a :class:`~rosmc_server.core.live.mirror.MissionMirror` current from the ROS graph.

Subscribes (each name behind ``prefix``, e.g. ``/replay``):
    ``/rosmc/mission_events`` (rosmc/MissionEvent): one message per accepted change.
    ``/rosmc/agent_states`` (rosmc/AgentStates): every robot's link and telemetry, and the
    server's revision (an event lost at the end of a burst shows there).
    ``/rosmc/replay/state`` (rosmc/ReplayState): only a replay publishes it; when the replay
    was moved (a seek, backwards too) the mirror starts again from the replay's mission.

Calls (on its own worker thread, never the caller's):
    ``/rosmc/get_mission`` (rosmc/GetMission): the snapshot, at start, after a revision gap,
    after a replaced mission, after the server restarted and after a replay was moved.

Watches ``/rosmc/get_mission`` on the master at start and once per ``check_period`` to tell
when the server went away or came back as a new process (then the mirror starts from its
snapshot; a process is told by its address and process id).
"""

from __future__ import annotations

import logging
import threading
import xmlrpc.client
from collections.abc import Callable
from typing import Any
from xmlrpc.client import ServerProxy

import rosgraph
import rosmc.msg as wire
import rospy

from ... import interface
from ...conversions import agent_statuses_from_msg, event_from_msg
from ...core import Library, MissionState
from ...core.live.mirror import MissionMirror
from .mission_client import MissionClient
from .worker import AsyncMissionClient, Outcome

_log = logging.getLogger(__name__)

ConnectionListener = Callable[[bool], None]


class MissionFollower:
    """Feeds a mission mirror from the mission server (or a replay); call :meth:`start`.

    The process must be a ROS node (:func:`~rosmc_server.ros.node_setup.init_node` or
    ``rospy.init_node``).
    Everything that waits on the network runs on worker threads; the mirror's listeners
    are called on rospy's or the worker's threads (see :class:`MissionMirror`).

    Args:
        prefix: Namespace before every name ("" for the live server, ``/replay`` for a replay).
        timeout: Seconds a snapshot fetch waits for the server.
        retry_period: Seconds between attempts while the server does not answer.
        check_period: Seconds between checks that the server is still the same process.
        on_connection: Called with True/False when the server appears or goes away.
        on_restart: Called with the revision a new server process is at, once the mirror
            holds its mission (on the worker thread).
        on_journal_alert: Called with the server's journal alert when it changes ("" once
            it clears): lost history, or a full disk that refuses changes (ROS thread).
    """

    def __init__(
        self,
        prefix: str = "",
        timeout: float = 5.0,
        retry_period: float = 2.0,
        check_period: float = 1.0,
        on_connection: ConnectionListener | None = None,
        on_restart: Callable[[int], None] | None = None,
        on_journal_alert: Callable[[str], None] | None = None,
    ) -> None:
        self.prefix = prefix
        self.mirror = MissionMirror(self._request_snapshot)
        self._fetcher = AsyncMissionClient(MissionClient(timeout, prefix), "rosmc-snapshot")
        self._retry_period = retry_period
        self._check_period = check_period
        self._on_connection = on_connection
        self._on_restart = on_restart
        self._on_journal_alert = on_journal_alert
        self._journal_alert = ""
        self._server_uri: str | None = None  # who answers now (None: nobody)
        self._known_uri: str | None = None  # who answered last
        self._restarted = False
        self._epoch = ""  # of the events heard so far
        self._seeks: int | None = None  # moves of the replay followed (None: none heard yet)
        self._closed = threading.Event()
        self._retry: threading.Timer | None = None
        self._library: Library | None = None
        self._subscribers = [
            rospy.Subscriber(
                interface.prefixed(interface.EVENTS_TOPIC, prefix),
                wire.MissionEvent,
                self._on_event,
                queue_size=10_000,
            ),
            rospy.Subscriber(
                interface.prefixed(interface.AGENT_STATES_TOPIC, prefix),
                wire.AgentStates,
                self._on_states,
                queue_size=1,
            ),
            rospy.Subscriber(
                interface.prefixed(interface.REPLAY_STATE_TOPIC, prefix),
                wire.ReplayState,
                self._on_replay_state,
                queue_size=10,
            ),
        ]
        self._watcher = threading.Thread(target=self._watch, name="rosmc-follow", daemon=True)

    @property
    def connected(self) -> bool:
        """The server answered the last check."""
        return self._server_uri is not None

    def start(self) -> None:
        """Ask for the first snapshot and start watching the server."""
        self.mirror.start()
        self._watcher.start()

    def library(self, on_done: Callable[[Outcome[Library]], None], fresh: bool = False) -> None:
        """Fetch the skill library without waiting (once; later calls answer from the cache,
        unless ``fresh``: after the server restarted, maybe with another library)."""

        def fetch(client: MissionClient) -> Library:
            if fresh:
                client.forget_library()
            return client.library()

        self._fetcher.submit(fetch, on_done)

    def refresh(self) -> None:
        """Fetch a new snapshot now (e.g. after a conflict the operator was told of)."""
        self._request_snapshot()

    def close(self) -> None:
        """Unsubscribe and stop the worker threads."""
        self._closed.set()
        for subscriber in self._subscribers:
            subscriber.unregister()
        if self._retry is not None:
            self._retry.cancel()
        self._fetcher.close()

    # -- snapshots -------------------------------------------------------------------------
    def _request_snapshot(self) -> None:
        if not self._closed.is_set():
            self._fetcher.submit(lambda client: client.fetch_mission(), self._on_snapshot)

    def _on_snapshot(self, outcome: Outcome[MissionState]) -> None:
        if outcome.value is not None:
            restarted, self._restarted = self._restarted, False
            self.mirror.on_snapshot(outcome.value, restarted=restarted)
            if restarted and self._on_restart is not None:
                self._on_restart(outcome.value.revision)
            return
        _log.warning("cannot fetch the mission (%s); trying again", outcome.error)
        if not self._closed.is_set():
            self._retry = threading.Timer(self._retry_period, self._request_snapshot)
            self._retry.daemon = True
            self._retry.start()

    # -- ROS callbacks -----------------------------------------------------------------------
    def _on_event(self, msg: wire.MissionEvent) -> None:
        epoch = str(getattr(msg, "epoch", ""))  # absent from events of older recordings
        if epoch and self._epoch and epoch != self._epoch:
            # The server resumed with lost history: revisions this mirror holds may hold
            # changes that are gone. Take its mission whatever its revision.
            _log.warning("the mission's history changed (epoch %s); fetching it", epoch)
            self._epoch = epoch
            self._restarted = True
            self._request_snapshot()
            return
        self._epoch = epoch or self._epoch
        try:
            event = event_from_msg(msg)
        except Exception:  # a malformed event must not kill the subscriber thread
            _log.exception("cannot read mission event at revision %d", msg.revision)
            return
        self.mirror.on_event(event)

    def _on_states(self, msg: wire.AgentStates) -> None:
        try:
            statuses = agent_statuses_from_msg(msg)
        except Exception:  # a malformed message must not kill the subscriber thread
            _log.exception("cannot read agent states")
            return
        self.mirror.on_agent_statuses(statuses)
        self.mirror.on_server_revision(int(msg.revision))
        alert = str(getattr(msg, "journal_alert", ""))  # absent from older recordings
        if alert != self._journal_alert:
            self._journal_alert = alert
            if self._on_journal_alert is not None:
                self._on_journal_alert(alert)

    def _on_replay_state(self, msg: wire.ReplayState) -> None:
        seeks = int(msg.seeks)
        before, self._seeks = self._seeks, seeks
        # The first state heard may tell of seeks made before the first fetch answered.
        if seeks == (before or 0) or self._closed.is_set():
            return
        # A replay moved back publishes revisions the mirror has seen, with other content:
        # its mission is taken whatever its revision, as a restarted server's is; the
        # robots' states it published for the new time stay.
        _log.info("the replay moved; fetching its mission")
        self._fetcher.submit(lambda client: client.fetch_mission(), self._on_moved_snapshot)

    def _on_moved_snapshot(self, outcome: Outcome[MissionState]) -> None:
        if outcome.value is not None:
            self.mirror.on_snapshot(outcome.value, moved=True)
        else:
            self._on_snapshot(outcome)  # says so and tries again

    # -- is the server there, and the same process? ----------------------------------------------
    def _watch(self) -> None:
        name = interface.service_name("get_mission", self.prefix)
        master = rosgraph.Master(rospy.get_name())
        while True:  # look at once: a server that restarts soon must be told from this one
            uri = server_process(master, name)
            if uri != self._server_uri:
                self._server_changed(uri)
            if self._closed.wait(self._check_period):
                return

    def _server_changed(self, uri: str | None) -> None:
        previous, self._server_uri = self._server_uri, uri
        if uri is not None:
            # A new process answers: its revisions may have begun anew.
            if self._known_uri is not None and uri != self._known_uri:
                _log.info("the mission server restarted; fetching its mission")
                self._restarted = True
                self._request_snapshot()
            self._known_uri = uri
        if (previous is None) != (uri is None) and self._on_connection is not None:
            self._on_connection(uri is not None)


def server_process(master: rosgraph.Master, service: str) -> str | None:
    """Who answers ``service`` now: its address and process id (None: nobody).

    The address alone does not tell a restarted server from the old one: a process
    started after a ``kill -9`` may be given the very port its predecessor had.
    """
    try:
        uri = str(master.lookupService(service))
        providers = dict(master.getSystemState()[2]).get(service) or []
        node_api = master.lookupNode(providers[0]) if providers else ""
        answer: Any = ServerProxy(node_api).getPid(master.caller_id) if node_api else None
    except (rosgraph.MasterException, OSError, xmlrpc.client.Error):
        return None
    pid = int(answer[2]) if isinstance(answer, list) and len(answer) == 3 else -1
    return f"{uri} pid {pid}"
