"""A client's live copy of the mission: the latest snapshot, then events in revision order.

:class:`MissionMirror` is what both GUIs, ``rosmc watch`` and replay viewers hold. It takes
snapshots, mission events and agent statuses as they arrive (from any thread, in any
order), applies every event exactly once with :func:`~.updates.apply_event`, asks for
one new snapshot when it sees a gap or a replaced mission, and tells its listeners what
changed as one :class:`~.updates.MirrorUpdate` per snapshot, event or status change. No
rospy or Qt: :class:`rosmc_server.ros.client.MissionFollower` feeds it from ROS.
"""

from __future__ import annotations

import logging
import threading
from collections import deque
from collections.abc import Callable, Mapping

from ..model.changes import MissionEvent
from ..model.state import MissionState
from ..robots.agent_status import AgentStatus
from .updates import (
    AgentStatusChanged,
    Listener,
    MirrorUpdate,
    MissionReset,
    apply_event,
    needs_snapshot,
)

_log = logging.getLogger(__name__)

# Events held while a snapshot is awaited. Past this the oldest go: the snapshot that is
# coming covers them, and if it does not, the gap asks for another.
MAX_PENDING_EVENTS = 100_000


class MissionMirror:
    """The mission as a client sees it, kept current from a snapshot and the event stream.

    Feed it with :meth:`on_snapshot` (a ``get_mission`` answer or the latched
    ``/rosmc/mission``), :meth:`on_event` (``/rosmc/mission_events``) and
    :meth:`on_agent_statuses` (``/rosmc/agent_states``). It calls ``request_snapshot``
    (which must not block: start a fetch and return) when it has no snapshot yet, when an
    event skips a revision, and when an event replaced the whole mission; never twice
    before a snapshot arrives. Events that arrive before the snapshot they follow are held
    and applied after it.

    Listeners are called in revision order, on the thread that fed the mirror, with the
    mirror's lock held: they must be quick (emit a Qt signal, stage a marker change) and
    must not call back into the feeding methods. :attr:`state` may be read from a listener,
    or from anywhere under :attr:`lock`.

    Args:
        request_snapshot: Called (with no lock held) when a fresh snapshot is needed.
    """

    def __init__(self, request_snapshot: Callable[[], None] | None = None) -> None:
        self.lock = threading.RLock()
        self._request_snapshot = request_snapshot
        self._state: MissionState | None = None
        self._pending: deque[MissionEvent] = deque(maxlen=MAX_PENDING_EVENTS)
        self._awaiting_snapshot = False
        self._statuses: dict[str, AgentStatus] = {}
        self._listeners: list[Listener] = []
        self._held_at_request = -1
        self._server_revision: int | None = None
        self.snapshots_requested = 0
        self.ignored_events = 0

    # -- reading ---------------------------------------------------------------------------
    @property
    def state(self) -> MissionState | None:
        """The mission at :attr:`revision` (None before the first snapshot); do not change it."""
        return self._state

    @property
    def revision(self) -> int | None:
        """The revision of :attr:`state` (None before the first snapshot)."""
        return None if self._state is None else self._state.revision

    @property
    def synced(self) -> bool:
        """A snapshot has arrived and no gap or replacement is waiting for the next one."""
        return self._state is not None and not self._awaiting_snapshot

    def agent_status(self, agent: str) -> AgentStatus | None:
        """The latest live status of ``agent``'s robot (None if never received)."""
        return self._statuses.get(agent)

    @property
    def agent_statuses(self) -> Mapping[str, AgentStatus]:
        """The latest live status of every robot heard of."""
        return dict(self._statuses)

    def subscribe(self, listener: Listener) -> Callable[[], None]:
        """Call ``listener`` with every update from now on; returns the unsubscribe call.

        A listener subscribed after the first snapshot gets a :class:`MissionReset` of the
        current mission at once, so it never starts from nothing.
        """
        with self.lock:
            self._listeners.append(listener)
            if self._state is not None:
                listener(MirrorUpdate(self._state.revision, (MissionReset(self._state),)))

        def unsubscribe() -> None:
            with self.lock:
                if listener in self._listeners:
                    self._listeners.remove(listener)

        return unsubscribe

    # -- feeding ---------------------------------------------------------------------------
    def start(self) -> None:
        """Ask for the first snapshot (if none came yet)."""
        with self.lock:
            need = self._state is None and self._claim_snapshot_request()
        if need:
            self._ask_snapshot()

    def on_snapshot(
        self, state: MissionState, *, restarted: bool = False, moved: bool = False
    ) -> None:
        """Take a full snapshot; older than what the mirror holds, it is ignored.

        The mirror keeps ``state`` (do not change it afterwards). Held events after its
        revision are applied on top of it. ``restarted``: the snapshot comes from a server
        that started anew (its revisions may have begun again), so it is taken whatever its
        revision, and held events are dropped, as are the robot statuses the old server
        gave (listeners hear each robot as unknown until the new server speaks of it).
        ``moved``: a replay moved to another time; its mission is taken whatever its
        revision and held events are dropped, but the robot statuses stay: the replay
        published those of the new time before it said that it moved, and a paused replay
        publishes none again.
        """
        with self.lock:
            if restarted or moved:
                self._pending.clear()
            if restarted:
                self._forget_statuses()
            stale = self._state is not None and state.revision < self._state.revision
            if not stale or restarted or moved:
                self._state = state
                self._notify(MirrorUpdate(state.revision, (MissionReset(state),)))
            # else: an answer to a fetch overtaken by events; the mirror is ahead of it.
            self._awaiting_snapshot = False
            self._drop_phantoms(max(state.revision, self.revision or 0))
            need = self._apply_pending()
        if need:
            self._ask_snapshot()

    def on_event(self, event: MissionEvent) -> None:
        """Take one mission event; it is applied now, held, or ignored if already seen."""
        with self.lock:
            self._pending.append(event)
            need = False if self._awaiting_snapshot else self._apply_pending()
            if self._state is None and not self._awaiting_snapshot:
                need = self._claim_snapshot_request()
        if need:
            self._ask_snapshot()

    def on_server_revision(self, revision: int) -> None:
        """The server says it is at ``revision`` (agent states carry it, at a steady rate).

        Events are published as they happen, so by the server's next word every event up
        to the revision it gave last time has arrived, unless one was lost (a subscriber
        that connected late, a dropped connection). A loss at the end of a burst shows no
        gap, so this is how it is noticed: the mirror then asks for a snapshot.
        """
        with self.lock:
            said_before, self._server_revision = self._server_revision, revision
            lagging = (
                self._state is not None
                and said_before is not None
                and self._state.revision < min(said_before, revision)
            )
            need = lagging and self._claim_snapshot_request()
        if need:
            _log.info("the mission mirror missed events up to revision %d; refetching", revision)
            self._ask_snapshot()

    def on_agent_statuses(self, statuses: Mapping[str, AgentStatus]) -> None:
        """Take the robots' latest statuses; listeners hear of those with news.

        A status whose only change is an age within the same whole second
        (:meth:`AgentStatus.news_since`) is kept without a word: the server publishes
        every robot's status twice a second, most of the time only to say it is current.
        """
        with self.lock:
            changes = []
            for agent, status in statuses.items():
                old = self._statuses.get(agent)
                self._statuses[agent] = status
                if status.news_since(old):
                    changes.append(AgentStatusChanged(old, status))
            if changes:
                self._notify(MirrorUpdate(self.revision or 0, tuple(changes)))

    # -- internals ---------------------------------------------------------------------------
    def _forget_statuses(self) -> None:
        """Drop every robot status heard so far; listeners hear them unknown (lock held)."""
        changes = tuple(
            AgentStatusChanged(old, AgentStatus(agent))
            for agent, old in self._statuses.items()
            if old != AgentStatus(agent)
        )
        self._statuses.clear()
        if changes:
            self._notify(MirrorUpdate(self.revision or 0, changes))

    def _apply_pending(self) -> bool:
        """Apply held events in order; True if a snapshot must be requested (lock held)."""
        state = self._state
        if state is None:
            return False
        while self._pending:
            ordered = sorted(self._pending, key=lambda e: e.revision)
            self._pending.clear()
            for index, event in enumerate(ordered):
                if event.revision <= state.revision:
                    continue  # seen already (in the snapshot or before)
                if event.revision > state.revision + 1 or needs_snapshot(event):
                    self._pending.extend(ordered[index:])
                    return self._claim_snapshot_request()
                changes = apply_event(state, event)
                self._notify(MirrorUpdate(event.revision, changes, event))
        return False

    def _claim_snapshot_request(self) -> bool:
        if self._awaiting_snapshot:
            return False
        self._awaiting_snapshot = True
        self.snapshots_requested += 1
        self._held_at_request = max((e.revision for e in self._pending), default=-1)
        return True

    def _drop_phantoms(self, revision: int) -> None:
        """Drop held events the server had not reached when it answered (lock held).

        The server publishes an event after committing it, so a snapshot asked for after
        an event arrived is at least that event's revision. Events held since before the
        request and still ahead of the answer came from elsewhere (a stray publisher, a
        server that has gone); waiting for them would ask for snapshots for ever.
        """
        phantoms = [e for e in self._pending if revision < e.revision <= self._held_at_request]
        if not phantoms:
            return
        self.ignored_events += len(phantoms)
        _log.warning(
            "ignored %d mission event(s) ahead of the server's mission (revision %d): "
            "another node publishes on the mission events topic?",
            len(phantoms),
            revision,
        )
        kept = [e for e in self._pending if e not in phantoms]
        self._pending.clear()
        self._pending.extend(kept)

    def _ask_snapshot(self) -> None:
        if self._request_snapshot is not None:
            self._request_snapshot()

    def _notify(self, update: MirrorUpdate) -> None:
        for listener in list(self._listeners):
            try:
                listener(update)
            except Exception:  # one broken view must not stop the others or the mirror
                _log.exception("a mission mirror listener failed at revision %d", update.revision)
