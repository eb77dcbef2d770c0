"""Republishing a recorded mission onto the ROS graph, as the mission server published it.

:class:`RecordingReplayer` publishes what the server recorded at log time ``t`` when the
replay's position (seconds since the recording started, advancing ``rate`` seconds per
second) reaches ``t``, so rviz, the command GUI and ``rosmc watch`` show the mission
evolving. It can be paused, resumed, moved (backwards too) and sped up while it runs
(keys of ``rosmc replay``, or its control service). After every seek, and at the start,
subscribers get the state at the position: the mission then (a snapshot, then the events
from there on), the robots' agent states, TF, the site and the score as last recorded.
It refuses to play onto names another node uses (a live mission server); a topic prefix
moves the replay out of their way.

Publishes (each name behind ``prefix``):
    ``/rosmc/mission`` (rosmc/Mission, latched): the mission at the start time (and after
    every seek), then the mission after every burst of events (rebuilt from the
    recording, as the server coalesces its snapshots).
    ``/rosmc/mission_events`` (rosmc/MissionEvent): every recorded event after the position.
    ``/rosmc/agent_states`` (rosmc/AgentStates): as recorded (the latest one at once).
    ``/rosmc/robot_reports`` (rosmc/RobotReport): as recorded.
    ``/tf`` (tf2_msgs/TFMessage): the robots' recorded transforms (``<prefix>/tf`` with a
    prefix: ``roslaunch rosmc rviz.launch ns:=/replay`` remaps rviz's ``/tf`` to it).
    ``/rosmc/sim/science`` (rosmc/ScienceState, latched), ``/rosmc/sim/world``
    (visualization_msgs/MarkerArray, latched): the site and the score, as recorded.
    ``/rosmc/replay/state`` (rosmc/ReplayState, latched): see :mod:`.replay_control`.

Services (behind ``prefix``):
    ``/rosmc/get_mission`` (rosmc/GetMission): the mission at the replay's position, so
    clients that start from it (``rosmc watch``, the GUIs) follow the replay as they follow
    a live server.
    ``/rosmc/get_library`` (rosmc/GetLibrary): the library the recording ran with.
    ``/rosmc/replay/control`` (rosmc/ReplayControl): pause, resume, seek, rate.

The replayer serves clients and ranks with the client in the layers. Its callers need no
rospy: :meth:`RecordingReplayer.run` makes the process a node itself and hands each event
over as a core :class:`~rosmc_server.core.MissionEvent`.
"""

from __future__ import annotations

import logging
import os
import threading
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from typing import Any

import rosmc.srv as wire_srv
import rospy

from .. import interface
from ..conversions import event_from_msg
from ..conversions.packing import PackedGetMissionResponse, PackedMission
from ..core import EventKind, InvalidRequest, MissionEvent, RosmcError
from ..recording import JournalRecord
from ..recording.history import MissionHistory
from ..recording.playback import PlaybackClock, PlaybackStatus, Playlist
from .graph_names import taken_names
from .node_setup import init_node
from .replay_control import ReplayControl
from .replay_library import GET_LIBRARY, serve_library
from .replay_mission import ReplayMission
from .replay_output import TYPES, ReplayOutput, first_telemetry
from .replay_progress import ReplayProgress

_log = logging.getLogger(__name__)

QUIET = 0.05
"""Seconds without events after which the rebuilt snapshot is published (as the server)."""
MAX_DELAY = 0.25
"""Longest a burst of events goes without a new snapshot."""
WARM_UP = 0.5
"""Seconds for subscribers to appear before the first message."""
CONNECT_TIMEOUT = 5.0
"""Longest the replay then waits for the subscribers it knows of to connect."""
LINGER = 1.0
"""Seconds the last messages get to reach their subscribers before the node leaves."""

GET_MISSION = interface.service_name("get_mission")

EventCallback = Callable[[int, MissionEvent | None, float], None]
"""Called with each replayed event: its revision, the event (None if it does not decode)
and its time in the recording (s)."""


class ReplayRefused(RosmcError):
    """Another node publishes on the names the replay would use."""


@dataclass(frozen=True)
class ReplayConfig:
    """How to play a recording back.

    Attributes:
        rate: Speed-up: 2.0 plays twice as fast as recorded.
        start: Seconds since the recording started to begin at.
        prefix: Put before every topic name ("" = the live names, e.g. ``/replay``).
        hold: At the end, stay (and keep serving) until stopped, instead of leaving.
        paused: Begin paused at ``start`` (the command GUI opens a recording so).
    """

    rate: float = 1.0
    start: float = 0.0
    prefix: str = ""
    hold: bool = False
    paused: bool = False

    def topic(self, name: str) -> str:
        """A recorded topic's name in this replay."""
        return interface.prefixed(name, self.prefix)


class RecordingReplayer:
    """Plays one recording onto the graph with :meth:`run`; steer it from any thread.

    Args:
        history: The recording's history (rebuilds the snapshots).
        records: The recording's records (:attr:`JournalResult.records`).
        config: Rate, start time, topic prefix, hold.
        on_event: Called with each event as it is published (see :data:`EventCallback`).
    """

    def __init__(
        self,
        history: MissionHistory,
        records: Sequence[JournalRecord],
        config: ReplayConfig,
        on_event: EventCallback | None = None,
    ) -> None:
        if not 0 <= config.start <= history.duration:
            raise InvalidRequest(
                f"the start must be between 0 and {history.duration:.2f} s (the recording's "
                f"length), got {config.start}"
            )
        self._history = history
        self._config = config
        self._on_event = on_event
        self._playlist = Playlist(records, history.start)
        self._clock = PlaybackClock(history.duration, config.start, config.rate)
        if config.paused:
            self._clock.pause()
        self._stop = threading.Event()
        self._lock = threading.RLock()  # the history, and what was published
        self._progress = ReplayProgress(self._lock)  # what the playing thread published
        self._output: ReplayOutput | None = None
        self._control: ReplayControl | None = None
        self._revision = -1  # of the last snapshot published on /rosmc/mission
        self._mission = ReplayMission(history, self._playlist, config.start)

    # -- steering (any thread) -------------------------------------------------------------
    def status(self) -> PlaybackStatus:
        """Where the replay is: position, rate, paused, seeks and the mission revision there."""
        with self._lock:
            return replace(self._clock.status(), revision=self._mission.current)

    def pause(self) -> PlaybackStatus:
        """Stop where it is; returns once every record due until there is out.

        A record that came due just before the pause is published after it by the playing
        thread; waiting for it keeps the answer's revision the one subscribers end with.
        """
        paused = self._clock.pause()
        playlist = self._playlist
        self._progress.await_due(
            lambda index: index < len(playlist) and playlist.offset(index) <= paused.position,
            self._stop,
        )
        return self.status()

    def resume(self) -> PlaybackStatus:
        """Go on; at the end of the recording, play it again from the start."""
        moved = self._clock.resume()
        self._progress.await_seek(moved.seeks, self._stop)
        return self.status()

    def seek(self, seconds: float, *, relative: bool = False) -> PlaybackStatus:
        """Move to ``seconds`` since the start (or from the position; clamped to the recording).

        Returns once subscribers have been sent the state at the new position (while the
        replay plays; at once before :meth:`run` or after it).

        Raises:
            InvalidRequest: ``seconds`` is not a number.
        """
        moved = self._clock.seek(seconds, relative=relative)
        self._progress.await_seek(moved.seeks, self._stop)
        return self.status()

    def set_rate(self, rate: float) -> PlaybackStatus:
        """Play ``rate`` times as fast as recorded from now on.

        Raises:
            InvalidRequest: The rate is not a sensible speed-up.
        """
        self._clock.set_rate(rate)
        return self.status()

    def mission_at(self, position: float) -> Any:
        """Move the replay's mission to ``position`` (s) and return its snapshot message there.

        What a seek publishes on ``/rosmc/mission`` (None if the recording holds no mission
        at that moment); the replay's thread calls it on every seek, tests and benchmarks
        may call it before :meth:`run`.
        """
        with self._lock:
            return self._mission.move_to(position)

    def stop(self) -> None:
        """End :meth:`run` early (thread-safe)."""
        self._stop.set()
        self._clock.close()

    # -- running --------------------------------------------------------------------------
    def check_names(self) -> None:
        """Refuse to play if any node publishes the replay's topics or serves its services.

        Raises:
            ReplayRefused: Another node uses one of the names (the message names it).
            ServerUnavailable: The ROS master does not answer.
        """
        names = [
            self._config.topic(name)
            for name in (
                *TYPES,
                GET_MISSION,
                GET_LIBRARY,
                interface.REPLAY_CONTROL_SERVICE,
                interface.REPLAY_STATE_TOPIC,
            )
        ]
        caller = rospy.get_name() if rospy.core.is_initialized() else "/rosmc_replay"
        taken = taken_names(names, caller)
        if taken:
            held = "; ".join(f"{name} by {', '.join(nodes)}" for name, nodes in taken.items())
            raise ReplayRefused(
                f"these names are in use already: {held}. Stop the live mission server, or "
                "replay under a prefix (--prefix /replay)"
            )

    def run(self) -> int:
        """Check the names, publish everything on time and return the last revision shown.

        Makes the process a ROS node first unless it is one already (the names are
        checked before that: joining the graph waits for a missing master forever).
        """
        self.check_names()
        init_node(f"rosmc_replay_{os.getpid()}")
        self._output = ReplayOutput(self._config.prefix, first_telemetry(self._playlist))
        service = rospy.Service(
            self._config.topic(GET_MISSION), wire_srv.GetMission, self._on_get_mission
        )
        library = serve_library(self._playlist, self._config.prefix)  # the recorded one
        self._control = ReplayControl(self, self._config.prefix)
        rospy.on_shutdown(self.stop)
        try:
            return self._play()
        finally:
            self._progress.playing(False)
            self._control.close()
            service.shutdown()
            library.shutdown()
            self._clock.close()

    def _play(self) -> int:
        self._progress.playing(True)
        if self._stop.wait(WARM_UP):
            return self._mission.current
        self._out().wait_for_subscribers(CONNECT_TIMEOUT, self._stop)
        if self._stop.is_set():
            return self._mission.current
        self._clock.start()
        playlist, seen, index = self._playlist, -1, 0
        last_snapshot = time.monotonic()
        while not self._stop.is_set():
            changes = self._clock.changes
            status = self._clock.status()
            if status.seeks != seen:
                seen = status.seeks
                index = self._jump(status)
                self._progress.next_record(index)
                continue
            if index >= len(playlist):
                if not self._config.hold:
                    self._announce()
                    break
                self._announce()
                self._clock.wait(None, changes)
                continue
            if not self._clock.wait(playlist.offset(index), changes):
                if self._clock.status().seeks == seen:  # paused, resumed, rate: say so
                    self._flush_snapshot()
                    self._announce()
                continue
            replaced = self._publish(playlist.records[index])
            index += 1
            self._progress.next_record(index)
            now = time.monotonic()
            quiet = (
                index == len(playlist)
                or (playlist.offset(index) - playlist.offset(index - 1)) / status.rate >= QUIET
            )
            if replaced or quiet or now - last_snapshot >= MAX_DELAY:
                self._flush_snapshot()
                last_snapshot = now
        self._stop.wait(LINGER)
        return self._mission.current

    # -- publishing -----------------------------------------------------------------------
    def _jump(self, status: PlaybackStatus) -> int:
        """Publish the state at ``status.position``; return the index of the record after it."""
        position = status.position
        with self._progress.condition:
            self.mission_at(position)  # built here, published (from the cache) below
            self._publish_snapshot(self._mission.current, position)
            self._out().publish_state_at(
                self._playlist, position, moved=status.seeks > 0, paused=status.paused
            )
            self._progress.seek_out(status.seeks)
        self._announce()
        _log.debug("replay: at %.2f s, revision %d", position, self._mission.current)
        return self._playlist.index_after(position)

    def _publish(self, record: JournalRecord) -> bool:
        """Publish one record; True if it replaced the mission (publish its snapshot now)."""
        topic = record.topic
        with self._lock:
            if topic not in (interface.MISSION_TOPIC, interface.EVENTS_TOPIC):
                self._out().publish(topic, record.message)
                return False
            revision = record.revision  # read from the bytes: a snapshot is decoded only if new
            if revision <= self._mission.current:
                return False  # part of the mission published already
            msg = record.message
            self._out().publish(topic, msg)
            self._mission.current = revision
            if topic == interface.MISSION_TOPIC:  # a revision the history could not rebuild
                self._revision = revision
                return False
            self._mission.stamp = msg.stamp.to_sec()
        if self._on_event is not None:
            self._on_event(revision, _decoded(msg), self._history.seconds(record.log_time))
        return bool(msg.kind == EventKind.MISSION_REPLACED)

    def _flush_snapshot(self) -> None:
        with self._lock:
            if self._mission.current > self._revision:
                self._publish_snapshot(self._mission.current)

    def _publish_snapshot(self, revision: int, position: float | None = None) -> None:
        with self._lock:
            msg = self._mission.message(revision, position)
        if msg is not None:
            self._out().publish(interface.MISSION_TOPIC, msg)
            self._revision = revision
            _log.debug("replay: snapshot of revision %d", revision)

    def _out(self) -> ReplayOutput:
        assert self._output is not None, "the replay publishes only while it runs"
        return self._output

    def _announce(self) -> None:
        if self._control is not None:
            self._control.publish(self.status())

    def _on_get_mission(self, _request: Any) -> Any:
        with self._lock:
            msg = self._mission.message(self._mission.current, self._clock.status().position)
        if isinstance(msg, PackedMission):
            return PackedGetMissionResponse(msg)
        return wire_srv.GetMissionResponse(mission=msg)


def _decoded(msg: Any) -> MissionEvent | None:
    try:
        return event_from_msg(msg)
    except RosmcError:
        return None
