"""What the ground does with each robot's periodic snapshot (``rosmc/ExecutorSnapshot``).

A snapshot re-synchronizes the numbering of commands and reports after either end
restarted, reconciles skill statuses after reports were lost for good, and carries two
digests the ground checks against its own: the queue hash (the ids the robot holds; a
repair is sent on a mismatch) and the status digest. Most snapshots leave the queue out
to spare the radio; the ground asks for it (``ReportAck.want_full``) when it must
reconcile: a new ground, or statuses that disagree with the digest.

Every method expects the server lock to be held.
"""

from __future__ import annotations

import logging
from collections.abc import Callable

import rosmc.msg as wire

from ..core import Mission, MissionEvent, RosmcError, SkillStatus
from ..core.robots.commands import CommandSpec, repair_command, synced_ids
from ..core.robots.link import InboundSequence, queue_hash, status_digest
from ..core.robots.reconcile import RobotSkill
from .agent_link import AgentLink, LinkHost, Operation

_log = logging.getLogger(__name__)
FULL_ASK_PERIOD = 5.0  # seconds at least between asks for a robot's whole queue on a digest


class SnapshotSync:
    """Takes the robots' snapshots for the ground link.

    Args:
        host: The mission server.
        clock: The ground link's clock (seconds).
        started: When the ground link started on that clock (older echoes are ignored).
        send: Queues a command for a robot (the queue repair).
        ack: Publishes a report ack of ``seq`` to ``link``'s robot.
        transmit: Sends what is due on ``link``.
    """

    def __init__(
        self,
        host: LinkHost,
        clock: Callable[[], float],
        started: float,
        send: Callable[[CommandSpec], None],
        ack: Callable[[AgentLink, int], None],
        transmit: Callable[[AgentLink], None],
    ) -> None:
        self._host = host
        self._clock = clock
        self._started = started
        self._send = send
        self._ack = ack
        self._transmit = transmit

    def on_snapshot(self, link: AgentLink, msg: wire.ExecutorSnapshot) -> None:
        """Take one snapshot of ``link``'s robot."""
        self._measure_round_trip(link, msg)
        stamp = msg.stamp.to_sec()
        if stamp < link.newest_stamp:
            # Older than something already heard (it queued behind newer reports): its
            # numbers would look like a robot restart and rewind the report stream.
            link.outbox.heard(self._clock())
            return
        link.newest_stamp = stamp
        agent = link.agent
        if link.outbox.robot_numbering(msg.last_command_seq, self._clock()):
            _log.info("link %s: robot executed commands up to %d", agent, msg.last_command_seq)
        fresh = link.reports is None or msg.last_report_seq < link.reports.last
        if msg.policy.kind == wire.LostLinkPolicy.UNSAID and link.snapshot is not None:
            msg.policy = link.snapshot.policy  # unchanged: the robot says it only now and then
        link.snapshot = msg
        if fresh:
            # Every report up to last_report_seq is reflected in the snapshot's statuses:
            # reconciled now, or once the robot sends them (a snapshot may leave them out).
            link.reports = InboundSequence(msg.last_report_seq)
            link.want_full = msg.queue_omitted
            self._ack(link, msg.last_report_seq)
        assert link.reports is not None
        caught_up = msg.last_report_seq == link.reports.last
        if not msg.queue_omitted:
            link.want_full = False
            if fresh or caught_up:
                self._reconcile(agent, msg)
        link.robot_hash = msg.queue_hash
        self.check_hash(link)
        if msg.queue_omitted and caught_up:
            self._check_digest(link, msg)
        if msg.queue_omitted and link.want_full and not fresh:
            # Asked for the queue and not given it: the ask is new, lost, or crossed this
            # snapshot. Ask (again) now, rather than with a later ack.
            self._ack(link, link.reports.last)
        self._transmit(link)

    def expected_hash(self, agent: str) -> str:
        """The queue hash the ground expects the robot to have."""
        return queue_hash(synced_ids(self._host.mission.state, agent))

    def expected_digest(self, agent: str) -> str:
        """The status digest the ground expects of the robot's queue."""
        state = self._host.mission.state
        return status_digest((i, int(state.skill(i).status)) for i in synced_ids(state, agent))

    def check_hash(self, link: AgentLink) -> None:
        """Repair the robot's queue when its hash differs from the ground's."""
        if link.outbox.pending() or not link.robot_hash:
            return  # commands in flight: the hashes may differ for now
        expected = self.expected_hash(link.agent)
        if expected == link.robot_hash:
            if link.mismatch:
                _log.info("link %s: queue hash agrees again (%s)", link.agent, expected)
            link.mismatch = False
            return
        if not link.mismatch:
            _log.warning(
                "link %s: robot queue hash %s differs from the ground's %s; repairing",
                link.agent,
                link.robot_hash,
                expected,
            )
        link.mismatch = True
        self._send(repair_command(self._host.mission.state, link.agent))

    def _check_digest(self, link: AgentLink, msg: wire.ExecutorSnapshot) -> None:
        """Ask for the robot's queue when its status digest differs from the ground's.

        With every report applied and nothing in flight the two agree; they differ after a
        report was lost for good (a robot restart) or statuses changed on the ground alone.
        Asked at most every :data:`FULL_ASK_PERIOD` s.
        """
        if link.outbox.pending() or link.mismatch:
            return
        now = self._clock()
        if now - link.full_asked < FULL_ASK_PERIOD:
            return
        if msg.status_digest != self.expected_digest(link.agent):
            link.full_asked, link.want_full = now, True
            _log.info("link %s: statuses differ from the robot's digest; asking", link.agent)

    def _measure_round_trip(self, link: AgentLink, msg: wire.ExecutorSnapshot) -> None:
        """Time from a stamped report ack to its echo, less what the robot held it."""
        if msg.echo_sent < self._started:
            return  # none yet, or sent by an earlier server
        sample = self._clock() - msg.echo_sent - max(0.0, msg.echo_held)
        if sample >= 0.0:
            link.outbox.round_trip_sample(sample)

    def _reconcile(self, agent: str, msg: wire.ExecutorSnapshot) -> None:
        queue = [
            RobotSkill(
                s.id,
                SkillStatus(s.status.value),
                max(1, s.attempt),
                s.status_text,
                s.started,
                s.finished,
            )
            for s in msg.queue
            if s.status.value in SkillStatus._value2member_map_
        ]
        conflicts: tuple[str, ...] = ()

        def reconcile(mission: Mission) -> MissionEvent | None:
            nonlocal conflicts
            event, result = mission.reconcile(agent, queue)
            conflicts = result.conflicts
            return event

        self._apply(reconcile)
        for conflict in conflicts:
            _log.warning("link %s: %s", agent, conflict)

    def _apply(self, operation: Operation) -> None:
        """Apply a robot-driven change; a refusal is logged, never raised into rospy."""
        try:
            self._host.apply(operation)
        except RosmcError as error:
            _log.warning("robot link: %s", error)
