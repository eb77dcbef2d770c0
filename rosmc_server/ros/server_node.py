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
    ``~broadcast_snapshots`` (bool): also send ``/rosmc/mission`` to every subscriber after
        changes (coalesced), as before per-subscriber snapshots (false; for benchmarks).
    ``~operators`` (list of str, or one string of names): nodes (full names, or prefixes
        ending in ``/`` or ``*``) that may call the operator services; empty (the default)
        lets every node in. Guards against mistakes, not attackers (see
        :mod:`rosmc_server.core.operators`).
    ``~mission_dir`` (str): the only directory (with its subdirectories) where SaveMission
        and LoadMission read or write files on the server's host (default ``missions/``);
        elsewhere, clients pass the document itself.
    ``~radio_key`` (str): the deployment's radio key file, which signs the radio side
        channel's datagrams (default ``$ROS_HOME/rosmc/radio.key``, made there if missing;
        a key given here must exist: see :mod:`rosmc_server.core.radio_key`).
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
import dataclasses
import logging
import sys
import threading
import time
from collections.abc import Callable, Sequence
from contextlib import AbstractContextManager

import rosmc.msg as wire
import rospy

from .. import interface
from ..conversions import (
    event_from_msg,
    library_to_msg,
    mission_from_msg,
    mission_to_msg,
    time_to_msg,
)
from ..conversions.event_packing import packed_event
from ..conversions.packing import PackedMission, SnapshotPacker
from ..core import (
    Library,
    Mission,
    MissionContent,
    MissionEvent,
    Unavailable,
    load_library,
)
from ..core.changes import EventKind
from ..core.commands import commands_for_event, default_policy_commands
from ..recording import JournalOptions, JournalWriter, default_journal_path, latest_state
from ..recording.high_water import RevisionMark, first_mark, read_mark, resumed_mark
from ..recording.recovery import ResumeReport
from . import station
from .agent_states import AgentStatePublisher
from .allocator import keep_large_blocks_apart
from .clock_watch import CLOCK_CHECK_PERIOD, ClockWatch
from .ground_link import GroundLink
from .heartbeat import Heartbeat
from .logging_bridge import bridge_logging_to_rosout
from .operator_services import OperatorServices
from .publishing import SnapshotPublisher
from .radio import node_radio_key
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
        self._building = threading.Lock()  # one snapshot build at a time
        self._resume_alert = ""  # what resuming the journal could not recover
        self._snapshot_after_resume = False
        self.mission, self._journal = self._open_journal()
        station.remember_journal(self._journal.path)
        if self._snapshot_after_resume:  # the file now written must start the mission
            self._journal.append_snapshot(self.snapshot_msg(), time.time_ns())
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
        Heartbeat(self.library.dynamic_agents).start()  # idle robots in coverage hear the ground
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
            if not self._journal.closed:
                self._journal.close()
            self._marks.close()

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
        state = self.mission.state
        # Bytes made once for the journal and the topic (a whole reorder is 10,000 moves).
        msg = packed_event(event, lambda skill_id: state.locate(skill_id)[0], self.epoch)
        stamp_ns = time.time_ns()
        try:
            self._journal.append_event(msg, stamp_ns)
            if event.kind is EventKind.MISSION_REPLACED:
                # The new mission is only in the snapshot: it must be durable now. Its
                # skills were serialized ahead (prepare_snapshot), off the lock.
                snapshot = self._packer.pack(
                    self.mission.state.content(), self.mission.revision, rospy.get_time()
                )
                self._snapshot = snapshot
                self._journal.append_snapshot(snapshot, stamp_ns)
            # The journal's high-water mark, kept apart; a replacement counts only with its
            # snapshot (a journal ending in the event alone leaves it out on resume).
            self._marks.record(event.revision)
        except Exception:
            _log.critical("cannot write the journal; shutting down to protect the mission")
            self.failed = self._stopping = True  # a supervisor restarts it: exit status 1
            # Shortly after, so that the caller hears this change failed (not a dropped link).
            threading.Timer(0.5, rospy.signal_shutdown, ("journal write failed",)).start()
            raise
        self._events.publish(msg)
        self._snapshots.changed(urgent=event.kind is EventKind.MISSION_REPLACED)
        for spec in commands_for_event(event, state):
            self.link.send(spec)

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
            revision = self.mission.revision
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
        return self._marks.epoch

    @property
    def journal_alert(self) -> str:
        """What resuming the journal lost and whether its disk is full ("" if neither)."""
        return "; ".join(a for a in (self._resume_alert, self._journal.space.alert()) if a)

    def _open_journal(self) -> tuple[Mission, JournalWriter]:
        options = JournalOptions(fsync=self.config.fsync, snapshot_every=self.config.snapshot_every)
        clock = rospy.get_time
        library = library_to_msg(self.library)  # journaled: a replay shows the mission with it
        if self.config.resume:
            if self.config.journal is None:
                raise ValueError("~resume needs ~journal: the journal file to continue")
            writer = JournalWriter.resume(self.config.journal, options, library)
            return self._resumed(writer), writer
        mission = Mission(self.library, MissionContent.empty(self.library), clock=clock)
        path = self.config.journal or default_journal_path(self.config.journal_dir)
        path.parent.mkdir(parents=True, exist_ok=True)
        snapshot = mission_to_msg(mission.state.content(), 0, time.time())
        writer = JournalWriter.create(path, snapshot, time.time_ns(), options, library)
        self._marks = RevisionMark(path, first_mark(0), options.fsync)
        return mission, writer

    def _resumed(self, writer: JournalWriter) -> Mission:
        """The mission a resumed journal holds; says once, loudly, what it could not recover.

        After lost revisions the mission goes on above the highest revision the journal
        holds (an operator may have seen it), and a snapshot records where it stands.
        """
        assert writer.recovered is not None
        latest = latest_state(writer.recovered)
        for note in latest.notes:
            _log.warning("%s", note)
        content, revision = mission_from_msg(latest.snapshot)
        mission = Mission(self.library, content, revision, clock=rospy.get_time)
        for event_msg in latest.events:
            mission.replay(event_from_msg(event_msg))
        mark = read_mark(writer.path)
        report = ResumeReport.of(
            writer.path, writer.recovered.damage, latest, writer.part_path, mark
        )
        if report.lost and not writer.damaged:  # later resumes start after the loss
            writer.start_next_part()
            report = dataclasses.replace(report, written_to=writer.part_path)
        if not report.clean:
            _log.error("%s", report.log_line())
            self._resume_alert = report.alert()
        # After lost revisions the resumed mission is a revision of its own, so that a view
        # that held lost changes is stale (refused, refetched) instead of taken as current.
        revision = report.next_revision - (0 if report.lost else 1)
        if revision > mission.revision:
            content = mission.state.content()
            mission = Mission(self.library, content, revision, clock=rospy.get_time)
        marked = resumed_mark(mark, mission.revision, report.lost > 0)  # new epoch if lost
        self._marks = RevisionMark(writer.path, marked, self.config.fsync)
        self._snapshot_after_resume = writer.needs_snapshot or not report.clean
        _log.info("resumed from %s at revision %d", writer.path, mission.revision)
        return mission


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
    rospy.init_node("mission_server", anonymous=False)
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
