"""Ground side of the robot links: commands out, acknowledgements and reports in.

Per dynamic agent, on the topics of :func:`rosmc_server.interface.ground_link`:

* publishes ``command`` (rosmc/RobotCommand) and ``report_ack`` (rosmc/ReportAck);
* subscribes ``ack`` (rosmc/RobotAck), ``report`` (rosmc/RobotReport) and
  ``snapshot`` (rosmc/ExecutorSnapshot);
* beacons to each robot over the radio side channel (UDP, :mod:`.radio`, registered as
  ``/rosmc/radio/ground``); a robot's beacon after a silence, or its first return beacon
  (it did not hear the ground), reconnects its topics and retransmits its pending
  commands at once, whatever TCP's backoff has grown to.

Commands are retransmitted with backoff until acknowledged; while a robot is out of
contact new commands wait unsent for it (:mod:`rosmc_server.core.robots.waiting`); reports are
applied once each and in order; the robot's periodic snapshot re-synchronizes
numbering after restarts and reconciles statuses after outages, and its queue
hash is checked against the ground's, with a repair sent on a mismatch
(:mod:`.snapshot_sync`).

Every method expects the server lock to be held; the subscriber callbacks take it.
"""

from __future__ import annotations

import logging
import time
from collections.abc import Callable, Iterable

import rosmc.msg as wire
import rospy

from ..common.ros.radio import GROUND, Radio, TopicListener, reconnect_in_background
from ..conversions import time_to_msg
from ..conversions.command_packing import command_msg
from ..core import Mission, RosmcError, SkillStatus, StorageFull, Transfer
from ..core.robots.commands import CommandKind, CommandSpec, queued_barriers
from ..core.robots.drop_log import DropLog
from ..core.robots.link import (
    Arrival,
    LinkReport,
    LinkStatus,
    Outbox,
    Outgoing,
)
from ..core.robots.radio import BEACON_PERIOD, ROBOT_SILENCE, ContactWatch
from ..core.robots.radio_key import RadioKey
from ..core.robots.waiting import collapse, waiting_work
from ..core.skills.policy import ground_contact_period, options_from_argument
from ..interface import ground_link
from .agent_link import AgentLink, LinkHost, Operation
from .command_records import command_record
from .snapshot_sync import SnapshotSync

_log = logging.getLogger(__name__)

# Seconds between stamped report acks to each robot: they refresh the round trip of a quiet
# link (the robot echoes them). Ground contact for the robots' lost-link policies is the
# server's Heartbeat (wall time, like this); the ground's asks for a whole queue go out when made.
HEARTBEAT_PERIOD = 10.0


class GroundLink:
    """The ground station's end of every robot link."""

    def __init__(
        self,
        host: LinkHost,
        agents: Iterable[str],
        radio_key: RadioKey,
        timeout: float = 3.0,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        self._host = host
        self._clock = clock
        self._started = clock()
        self._links: dict[str, AgentLink] = {}
        self._next_heartbeat = self._next_beacon = 0.0
        self._contact = ContactWatch(silence=ROBOT_SILENCE)
        self._dropped_reports = DropLog("robot report")  # counted, warned at a limited rate
        self._snapshots = SnapshotSync(
            host,
            clock,
            self._started,
            self.send,
            lambda link, seq: link.report_ack_pub.publish(self._report_ack(link.agent, seq)),
            self._transmit,
        )
        for agent in agents:
            topics = ground_link(agent)
            link = AgentLink(
                agent,
                Outbox(timeout=timeout),
                rospy.Publisher(topics.command, wire.RobotCommand, queue_size=100),
                rospy.Publisher(topics.report_ack, wire.ReportAck, queue_size=100),
            )
            handlers = (
                (topics.ack, wire.RobotAck, self._on_ack),
                (topics.report, wire.RobotReport, self._on_report),
                (topics.snapshot, wire.ExecutorSnapshot, self._on_snapshot),
            )
            link.listeners = [
                TopicListener(topic, msg_type, self._guarded(handler, agent), queue_size=100)
                for topic, msg_type, handler in handlers
            ]
            self._links[agent] = link
        self.radio = Radio(GROUND, self._on_beacon, key=radio_key)

    @property
    def _mission(self) -> Mission:
        return self._host.mission

    # -- queries -------------------------------------------------------------
    def status(self, agent: str) -> LinkStatus:
        """UNKNOWN, UP or DOWN for ``agent``."""
        return self._links[agent].outbox.status(self._clock())

    def details(self, agent: str) -> tuple[LinkReport, AgentLink]:
        """The link report and tracked details of ``agent``, for display."""
        link = self._links[agent]
        return link.outbox.report(self._clock()), link

    def radio_dropped(self, agent: str) -> int:
        """Radio datagrams dropped on ``agent``'s link: by the robot (as its snapshot says)
        and by the ground among those that named the robot."""
        snapshot = self._links[agent].snapshot
        robot = int(getattr(snapshot, "radio_dropped", 0)) if snapshot is not None else 0
        return robot + self.radio.dropped_from(agent)

    def contact_period(self, agent: str) -> float:
        """Seconds between the ground's beats to ``agent``, per its lost-link policy.

        Callable without the server lock (the heartbeat's thread): it reads two fields.
        """
        link = self._links[agent]
        return ground_contact_period(link.asked_after, _reported_after(link.snapshot))

    def expected_hash(self, agent: str) -> str:
        """The queue hash the ground expects the robot to have."""
        return self._snapshots.expected_hash(agent)

    # -- sending -------------------------------------------------------------
    def send(self, spec: CommandSpec) -> None:
        """Queue a command for its robot; it goes out as soon as the link allows."""
        link = self._links[spec.agent]
        if spec.kind is CommandKind.SET_OPTIONS:
            # Beat for the new policy at once: the robot keeps it before the ground hears so.
            link.asked_after = options_from_argument(spec.argument)[0].acts_after
        if spec.kind is CommandKind.BARRIERS and spec.barriers == link.barriers_sent:
            return  # the robot already has exactly these barriers
        if spec.kind in (CommandKind.UPLOAD, CommandKind.BARRIERS, CommandKind.SYNC_STATE):
            link.barriers_sent = spec.barriers
        state = self._mission.state
        msg = command_msg(spec, lambda skill_id: state.locate(skill_id)[0])
        now = self._clock()
        collapsed = collapse(link.outbox, msg)
        for withdrawn in collapsed.withdrawn:
            self._record(wire.CommandRecord.CANCELLED, withdrawn)
        if collapsed.kept is None:
            self._record(wire.CommandRecord.CANCELLED, link.outbox.prepare(msg, now))
        else:
            self._record(wire.CommandRecord.ASKED, link.outbox.enqueue(collapsed.kept, now))
        self._transmit(link)

    def _record(self, event: int, item: Outgoing[wire.RobotCommand], result: int = 0) -> None:
        """Journal ``item`` (times on the ground's wall clock)."""
        wall = time.time()
        asked = wall - (self._clock() - item.asked)
        delivered = wall if event == wire.CommandRecord.DELIVERED else 0.0
        self._host.record_command(command_record(event, item, asked, delivered, result))

    def waiting_work(self, agent: str) -> int:
        """How much work (uploads, take-backs, retries, skips) waits unsent for ``agent``."""
        return waiting_work(self._links[agent].outbox)

    def tick(self) -> None:
        """Retransmit whatever is due; repeat report acks as the ground's heartbeat."""
        now = self._clock()
        heartbeat = now >= self._next_heartbeat
        if heartbeat:
            self._next_heartbeat = now + HEARTBEAT_PERIOD
        beacon = now >= self._next_beacon
        if beacon:
            self._next_beacon = now + BEACON_PERIOD
        for link in self._links.values():
            if beacon:
                self.radio.beacon(link.agent)
            self._transmit(link)
            if heartbeat and link.reports is not None:
                # Robots judge ground contact by what they hear; this keeps a quiet
                # but healthy link from looking lost.
                link.report_ack_pub.publish(self._report_ack(link.agent, link.reports.last))

    def resend_pending_transfers(self) -> None:
        """After a restart, ask again for the uploads and removals the journal shows pending."""
        state = self._mission.state
        for agent in self._links:
            task = state.task(agent)
            uploading = tuple(s for s in task if s.transfer is Transfer.UPLOADING)
            removing = tuple(s.id for s in task if s.transfer is Transfer.REMOVING)
            if uploading:
                barriers = queued_barriers(state, agent)
                self.send(CommandSpec(agent, CommandKind.UPLOAD, uploading, barriers=barriers))
            if removing:
                self.send(CommandSpec(agent, CommandKind.UNSYNC, skill_ids=removing))

    def _transmit(self, link: AgentLink) -> None:
        for item in link.outbox.due(self._clock()):
            item.payload.seq = item.seq
            item.payload.stamp = time_to_msg(time.time())
            link.command_pub.publish(item.payload)

    # -- receiving -----------------------------------------------------------
    def _on_beacon(self, sender: str, returning: bool) -> None:
        link = self._links.get(sender)
        if link is None or not self._contact.heard(sender, self._clock(), returning):
            return
        # The robot is back after a silence. Its stalled connections would resume only
        # at TCP's next retransmission, which backs off to minutes: connect afresh.
        how = "its return beacon" if returning else "a beacon after a silence"
        reconnect_in_background(link.listeners, f"the ground hears {sender} again ({how})")
        with self._host.locked():
            link.outbox.contact_returned(self._clock())
            self._transmit(link)

    def _guarded(
        self, handler: Callable[[str, object], None], agent: str
    ) -> Callable[[object], None]:
        def callback(msg: object) -> None:
            try:
                with self._host.locked():
                    handler(agent, msg)
            except Exception:  # a bad message must never kill the subscriber thread
                _log.exception("link %s: failed to handle a %s", agent, type(msg).__name__)

        return callback

    def _on_ack(self, agent: str, msg: wire.RobotAck) -> None:
        link = self._links[agent]
        link.newest_stamp = max(link.newest_stamp, msg.stamp.to_sec())
        if link.outbox.early(msg.seq):
            # An earlier answer was lost: the outbox has the robot answer them all again.
            _log.info("link %s: answer to command %d came before an earlier one", agent, msg.seq)
        item = link.outbox.acknowledge(msg.seq, self._clock())
        if item is None:
            return  # early, or the answer to a retransmission already processed
        self._record(wire.CommandRecord.DELIVERED, item, msg.result)
        if msg.result != wire.RobotAck.ACCEPTED:
            link.last_error = msg.error or "; ".join(msg.rejection_reasons)
            _log.warning("link %s: command %d refused: %s", agent, msg.seq, link.last_error)
        command = item.payload
        if command.type == CommandKind.UPLOAD:
            self._upload_answered(agent, command, msg)
        elif command.type == CommandKind.UNSYNC and self._removing(agent):
            # (An UNSYNC that only cleans up a cancelled upload needs no answer.)
            removed = [] if msg.result == wire.RobotAck.REJECTED else list(msg.accepted_ids)
            self._apply(lambda m: m.confirm_unsynchronized(agent, removed))
        link.robot_hash = msg.queue_hash
        self._snapshots.check_hash(link)

    def _upload_answered(self, agent: str, command: wire.RobotCommand, ack: wire.RobotAck) -> None:
        sent = [s.id for s in command.skills]
        uploading = self._uploading(agent)
        taken = set() if ack.result == wire.RobotAck.REJECTED else set(ack.accepted_ids)
        accepted = [i for i in sent if i in taken and i in uploading]
        if accepted and uploading[: len(accepted)] == accepted:
            self._apply(lambda m: m.confirm_synchronized(agent, accepted))
        refused = [i for i in sent if i not in taken and i in self._uploading(agent)]
        if refused:
            # Everything after a refused skill goes back too: the synchronized
            # section must stay a prefix of the task.
            pending = self._uploading(agent)
            tail = pending[pending.index(refused[0]) :]
            reason = ack.error or next(iter(ack.rejection_reasons), "refused by the robot")
            self._apply(lambda m: m.decline_synchronize(agent, tail, reason))

    def _removing(self, agent: str) -> bool:
        return any(s.transfer is Transfer.REMOVING for s in self._mission.state.task(agent))

    def _uploading(self, agent: str) -> list[str]:
        return [s.id for s in self._mission.state.task(agent) if s.transfer is Transfer.UPLOADING]

    def _on_report(self, agent: str, msg: wire.RobotReport) -> None:
        link = self._links[agent]
        link.outbox.heard(self._clock())
        link.newest_stamp = max(link.newest_stamp, msg.stamp.to_sec())
        if link.reports is None:
            return  # wait for the robot's snapshot to learn its numbering
        if link.reports.classify(msg.seq) is Arrival.NEXT:
            if msg.skill_id in self._uploading(agent):
                return  # it overtook the upload's ack (another topic); the robot resends it
            try:
                self._host.record_report(msg)
            except StorageFull:  # unacknowledged, the robot sends it again
                return
            link.reports.accept(msg.seq)
            self._apply_report(msg)
        link.report_ack_pub.publish(self._report_ack(agent, link.reports.last))

    def _apply_report(self, msg: wire.RobotReport) -> None:
        try:
            status = SkillStatus(msg.status.value)
        except ValueError:
            warning = self._dropped_reports.drop(
                "its status is not one this server knows",
                f"from {msg.agent} with unknown status {msg.status.value}",
                self._clock(),
            )
            if warning is not None:
                _log.warning("robot link: %s", warning)
            return
        stamp = msg.stamp.to_sec()
        self._apply(
            lambda m: m.report_status(
                msg.skill_id,
                status,
                attempt=msg.attempt or None,
                text=msg.status_text,
                stamp=stamp,
                started=msg.started,
                finished=msg.finished,
            )
        )

    def _on_snapshot(self, agent: str, msg: wire.ExecutorSnapshot) -> None:
        self._snapshots.on_snapshot(self._links[agent], msg)

    def _report_ack(self, agent: str, seq: int) -> wire.ReportAck:
        """A report ack stamped with the ground's clock (echoed back for the round trip)."""
        link = self._links[agent]
        return wire.ReportAck(
            agent=agent,
            seq=seq,
            sent=self._clock(),
            want_full=link.want_full,
            link_timeout=link.outbox.timeout,
        )

    def _apply(self, operation: Operation) -> None:
        """Apply a robot-driven change; a refusal is logged, never raised into rospy."""
        try:
            self._host.apply(operation)
        except RosmcError as error:
            _log.warning("robot link: %s", error)


def _reported_after(snapshot: wire.ExecutorSnapshot | None) -> float | None:
    """The silence after which the robot says its policy acts (None: never, or unsaid)."""
    if snapshot is None:
        return None
    policy = snapshot.policy
    if policy.kind in (wire.LostLinkPolicy.UNSAID, wire.LostLinkPolicy.CONTINUE):
        return None
    return float(policy.after)
