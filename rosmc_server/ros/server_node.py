"""The mission server node: owns the mission, journals every change, talks to robots.

Node ``/rosmc/mission_server``.

Services: one per operator operation, see :mod:`rosmc_server.ros.operator_services`
(``/rosmc/add_skill`` ... ``/rosmc/get_library``).

Publishes:
    ``/rosmc/mission_events`` (rosmc/MissionEvent): one per accepted change.
    ``/rosmc/mission`` (rosmc/Mission): the current snapshot to each subscriber as it
        connects; after that only a replaced mission (see :mod:`.publishing`).
    ``/rosmc/agent_states`` (rosmc/AgentStates): every agent's state at ``~agent_state_rate``.
    The robot links' command and report_ack topics (see :mod:`.ground_link`).

Journals, beside every change: agent states on change, TF of the robots at 2 Hz, the
simulator's science state and world markers on change (see :mod:`.recorder`), and each
command for a robot when asked and when delivered (``/rosmc/robot_commands``).

Subscribes:
    ``/<agent>/telemetry`` (rosmc/Telemetry) and the robot links' ack, report and
    snapshot topics; ``/tf``, ``/rosmc/sim/science`` and ``/rosmc/sim/world`` (to journal);
    ``/rosmc/site`` (rosmc/SiteMap, latched): the site skill targets are checked against
    (see :mod:`.site_listener`).

Parameters (private):
    ``~library`` (str): skill library YAML (default: the shipped Mars team library).
    ``~journal`` (str): journal file; "" = a new timestamped file in ``~journal_dir``.
    ``~journal_dir`` (str): where new journals go (default: ``bags/`` of the package).
    ``~resume`` (bool): continue from ``~journal`` (its last part file), recovering what a
        crash cut short; damage is skipped, said once as an ERROR and kept for GetMission's
        ``journal_alert`` (``rosmc status``).
    ``~link_timeout`` (float, s): silence after which a robot link is DOWN (3.0).
    ``~agent_state_rate`` (float, Hz): rate of ``/rosmc/agent_states`` (2.0).
    ``~fsync`` (bool): fsync the journal on every change (survives power loss; true).
    ``~snapshot_every`` (int): mission events between two full snapshots in the journal (500).
    ``~journal_reserve`` (int, bytes): free space on the journal's disk below which changes
        are refused (1 MiB); a change bigger than it meets the full disk mid-write instead
        and is never acknowledged (the server exits and resumes without it).
    ``~broadcast_snapshots`` (bool): also send ``/rosmc/mission`` to every subscriber after
        changes (coalesced), as before per-subscriber snapshots (false; for benchmarks).
    ``~operators`` (list of str, or one string of names): nodes (full names, or prefixes
        ending in ``/`` or ``*``) that may call the operator services; empty (the default)
        lets every node in. Guards against mistakes, not attackers (see
        :mod:`rosmc_server.core.rules.operators`).
    ``~mission_dir`` (str): the only directory (with its subdirectories) where SaveMission
        and LoadMission read or write files on the server's host (default ``missions/``);
        elsewhere, clients pass the document itself.
    ``~radio_key`` (str): the deployment's radio key file, which signs the radio side
        channel's datagrams (default ``$ROS_HOME/rosmc/radio.key``, made there if missing;
        a key given here must exist: see :mod:`rosmc_server.core.robots.radio_key`).
    ``~cwd`` (str): relative paths above are resolved against it (launch files pass the
        directory the user typed the command in; see :mod:`.station`).
    ``~station_journal`` (str): set by a launch file that restarts the server: a server that
        finds a journal there resumes it (see :mod:`.station`).

Every accepted change is journaled (and flushed) before its service answers.
If the journal cannot be written, the change is reported as failed and the
node shuts down, so that no change is ever acknowledged without being durable.
"""

from __future__ import annotations

import argparse
import logging
import sys
import threading
import time
from collections.abc import Callable, Sequence
from contextlib import AbstractContextManager

import rosmc.msg as wire
import rospy

from .. import interface
from ..common.ros import station
from ..common.ros.graph_join import join_graph
from ..common.ros.logging_bridge import bridge_logging_to_rosout
from ..common.ros.radio import node_radio_key
from ..conversions import library_to_msg, time_to_msg
from ..conversions.packing import PackedMission, SnapshotPacker
from ..core import (
    Library,
    Mission,
    MissionContent,
    MissionEvent,
    Unavailable,
    load_library,
)
from ..core.model.changes import EventKind
from ..core.robots.commands import commands_for_event, default_policy_commands
from ..recording import JournalOptions, default_journal_path
from ..recording.mission_journal import MissionJournal
from .agent_states import AgentStatePublisher
from .allocator import keep_large_blocks_apart
from .clock_watch import CLOCK_CHECK_PERIOD, ClockWatch
from .ground_link import GroundLink
from .heartbeat import Heartbeat
from .operator_services import OperatorServices
from .publishing import SnapshotPublisher
from .recorder import TelemetryRecorder
from .server_config import ServerConfig
from .site_listener import SiteListener

_log = logging.getLogger(__name__)


class MissionServer:
    """Owns the mission; every change goes through :meth:`apply` under one lock."""

    def __init__(self, config: ServerConfig, library: Library) -> None:
        self.config = config
        self.library = library
        self._stopping = False  # first: robot-link callbacks may arrive during construction
        self.failed = False  # the journal failed: the process exits with status 1
        self._lock = threading.RLock()
        self._packer = SnapshotPacker()
        self._snapshot: PackedMission | None = None  # the newest one built
        self._pending_snapshot: PackedMission | None = None  # a replacement's, until durable
        self._building = threading.Lock()  # one snapshot build at a time
        self._resume_alert = ""  # what resuming the journal could not recover
        self._mission, self._mission_journal = self._open_journal()
        self._journal = self._mission_journal.writer
        station.remember_journal(self._journal.path)
        self._events = rospy.Publisher(interface.EVENTS_TOPIC, wire.MissionEvent, queue_size=1000)
        self._snapshots = SnapshotPublisher(
            interface.MISSION_TOPIC,
            self.snapshot_msg,
            on_built=self._journal_snapshot,
            broadcast_changes=config.broadcast_snapshots,
        )
        key = node_radio_key(config.radio_key, "mission server")
        self.link = GroundLink(self, library.dynamic_agents, key, timeout=config.link_timeout)
        self._recorder = TelemetryRecorder(lambda: self._journal, frozenset(library.dynamic_agents))
        self._agent_states = AgentStatePublisher(
            self, config.agent_state_rate, on_published=self._recorder.agent_states
        )
        self._services = OperatorServices(self)
        self._clock_watch = ClockWatch()

    # -- lifecycle -----------------------------------------------------------------
    def start(self) -> None:
        """Start publishing, serving and talking to robots."""
        with self._lock:
            self.link.resend_pending_transfers()
            for spec in default_policy_commands(self.library):  # out when each robot links
                self.link.send(spec)
        self._snapshots.start()
        self._agent_states.start()
        # Idle robots in coverage hear the ground, often enough for their lost-link policy.
        Heartbeat(self.library.dynamic_agents, self.link.contact_period).start()
        self._recorder.start()
        self._services.advertise()
        self._site = SiteListener(self, lambda: self._journal)
        threading.Thread(target=self._tick_link, name="link", daemon=True).start()
        _log.info(
            "mission server ready: library %s, %d agents, revision %d, journal %s",
            self.library.name, len(self.library.dynamic_agents), self.mission.revision,
            self._journal.path,
        )  # fmt: skip

    def shutdown(self) -> None:
        """Close the journal cleanly (a complete, indexed MCAP file)."""
        with self._lock:
            self._stopping = True
            self._snapshots.stop()
            self._recorder.stop()
            self._mission_journal.close()

    def _tick_link(self) -> None:
        next_clock_check = 0.0
        while not rospy.is_shutdown() and not self._stopping:
            with self._lock:
                self.link.tick()
            if time.monotonic() >= next_clock_check:
                next_clock_check = time.monotonic() + CLOCK_CHECK_PERIOD
                self._clock_watch.check()
            time.sleep(0.05)

    # -- the one way to change the mission ------------------------------------------
    @property
    def mission(self) -> Mission:
        """The mission; Unavailable once the journal failed (the mission then holds a
        change that is not durable, which nobody may see)."""
        if self.failed:
            raise Unavailable("the mission server is stopping: its journal cannot be written")
        return self._mission

    def locked(self) -> AbstractContextManager[object]:
        """The server lock (re-entrant)."""
        return self._lock

    def apply(self, operation: Callable[[Mission], MissionEvent | None]) -> MissionEvent | None:
        """Run ``operation`` on the mission and record the event it returns.

        The event is journaled (flushed) and published, and the robot commands
        it implies are queued, all before this returns. A RosmcError raised by
        the operation propagates with the mission unchanged.
        """
        with self._lock:
            if self._stopping:
                raise Unavailable("the mission server is shutting down")
            self._journal.require_space()  # a change the journal cannot hold is never applied
            event = operation(self.mission)
            if event is not None:
                self._record(event)
            return event

    def _record(self, event: MissionEvent) -> None:
        try:
            msg = self._mission_journal.record(event, self._mission, self._replacement_snapshot)
        except Exception:
            # The mission holds a change that is not durable: from now on nothing shows it
            # (``mission`` raises), and the process exits for a supervisor to resume it.
            _log.critical("cannot write the journal; shutting down to protect the mission")
            self.failed = self._stopping = True  # a supervisor restarts it: exit status 1
            self._snapshot = None
            # Shortly after, so that the caller hears this change failed (not a dropped link).
            threading.Timer(0.5, rospy.signal_shutdown, ("journal write failed",)).start()
            raise
        if event.kind is EventKind.MISSION_REPLACED:  # durable now: it may be shown
            self._snapshot, self._pending_snapshot = self._pending_snapshot, None
        state = self._mission.state
        self._events.publish(msg)
        self._snapshots.changed(urgent=event.kind is EventKind.MISSION_REPLACED)
        for spec in commands_for_event(event, state):
            self.link.send(spec)

    def _replacement_snapshot(self, mission: Mission) -> PackedMission:
        """The snapshot journaled with a change that replaces the mission. Its skills were
        serialized ahead (prepare_snapshot), off the lock; kept only once it is durable."""
        snapshot = self._packer.pack(mission.state.content(), mission.revision, rospy.get_time())
        self._pending_snapshot = snapshot
        return snapshot

    def _journal_snapshot(self, snapshot: wire.Mission) -> None:
        """Journal a snapshot built after changes when one is due, off the service path.

        Building a snapshot of a large mission takes far longer than a service
        call may; the journal's reader accepts events written before a snapshot
        of an older revision.
        """
        self._journal.append_due_snapshot(snapshot, time.time_ns())

    def record_report(self, msg: wire.RobotReport) -> None:
        """Journal a robot report (the audit trail of what robots said)."""
        self._journal.append_report(msg, time.time_ns())

    def record_command(self, msg: wire.CommandRecord) -> None:
        """Journal a command for a robot: asked, delivered or cancelled."""
        if not self._journal.closed:
            self._journal.append_command(msg, time.time_ns())

    def snapshot_msg(self) -> PackedMission:
        """The full mission as a message, stamped now.

        Built once per revision (only the skills changed since the last one are
        serialized, outside the server lock) and shared by the latched topic, every
        GetMission answer and the journal.
        """
        with self._lock:
            revision = self.mission.revision  # Unavailable once the journal failed
            built = self._snapshot
            fresh = built is not None and built.revision == revision
            content = None if fresh else self.mission.state.content()
        if content is not None:
            with self._building:  # a second caller waits for this build and reuses it
                built = self._snapshot
                if built is None or built.revision < revision:
                    built = self._packer.pack(content, revision, 0.0)
                    self._snapshot = built
        assert built is not None
        return PackedMission(built.revision, time_to_msg(rospy.get_time()), built.body)

    def drop_snapshot(self) -> None:
        """Let the snapshot's bytes go while a load reads its document (megabytes each).

        A snapshot asked for before the load ends, or after a load that failed, is then
        serialized afresh. Kept while the publisher has one to build (after a change just
        before, such as the previous load): it would serialize the mission again.
        """
        if not self._snapshots.idle:
            return
        with self._building:
            self._snapshot = None
            self._packer.forget()

    def prepare_snapshot(self, content: MissionContent) -> None:
        """Serialize a mission about to replace this one (a load), outside the lock."""
        self._packer.prepare(content)

    # -- journal -------------------------------------------------------------------
    @property
    def epoch(self) -> str:
        """The mission's history: new whenever a resume lost history."""
        return self._mission_journal.epoch

    @property
    def journal_alert(self) -> str:
        """What resuming the journal lost and whether its disk is full ("" if neither)."""
        return "; ".join(a for a in (self._resume_alert, self._journal.space.alert()) if a)

    def _open_journal(self) -> tuple[Mission, MissionJournal]:
        options = JournalOptions(
            fsync=self.config.fsync,
            snapshot_every=self.config.snapshot_every,
            reserve_bytes=self.config.journal_reserve,
        )
        library = library_to_msg(self.library)  # journaled: a replay shows the mission with it
        if self.config.resume:
            if self.config.journal is None:
                raise ValueError("~resume needs ~journal: the journal file to continue")
            resumed = MissionJournal.resume(
                self.config.journal, self.library, options, library, clock=rospy.get_time
            )
            self._resume_alert = resumed.report.alert()
            return resumed.mission, resumed.journal
        mission = MissionJournal.new_mission(self.library, clock=rospy.get_time)
        path = self.config.journal or default_journal_path(self.config.journal_dir)
        path.parent.mkdir(parents=True, exist_ok=True)
        return mission, MissionJournal.create(path, mission, options, library)


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of ``mission_server``."""
    args = rospy.myargv(argv if argv is not None else sys.argv)
    parser = argparse.ArgumentParser(
        prog="mission_server",
        description="ROSMC mission server. Settings are private ROS parameters "
        "(_library:=..., _journal:=..., _resume:=true).",
    )
    parser.parse_args(args[1:])
    keep_large_blocks_apart()
    join_graph("mission_server", anonymous=False)
    bridge_logging_to_rosout()
    config = ServerConfig.from_params()
    try:
        server = MissionServer(config, load_library(config.library))
    except Exception as error:  # report start-up failures in one line, then exit
        _log.critical("mission server cannot start: %s", error)
        return 1
    rospy.on_shutdown(server.shutdown)
    server.start()
    rospy.spin()
    return 1 if server.failed else 0
