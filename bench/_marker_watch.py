"""What ``bench_markers.py`` runs beside the marker node: what rviz receives, and the robots.

:class:`UpdateWatch` subscribes ``/rosmc/markers/update`` as rviz does and keeps every
update that carries something (time, inserted interactive markers, pose-only updates,
erases), ``/rosmc/markers/icons`` (status icons) and ``/rosmc/mission_events`` (arrival
time per revision). :func:`team_motion` plays 20 robots as the simulator does: TF
``map -> <robot>/base_link`` and ``/<robot>/telemetry`` at 10 Hz, every message different.
:class:`FakeRobot` plays one robot's end of the robot link: it acknowledges uploads and
reports the status changes the benchmark asks for.
"""

from __future__ import annotations

import math
import threading
import time
from dataclasses import dataclass, field
from typing import Any


@dataclass
class Update:
    """One non-empty ``InteractiveMarkerUpdate`` as received."""

    at: float
    markers: tuple[str, ...]
    poses: tuple[str, ...]
    erases: tuple[str, ...]


@dataclass
class UpdateWatch:
    """Arrival times of mission events (by revision), marker updates and icon arrays."""

    updates: list[Update] = field(default_factory=list)
    icons: list[tuple[float, int]] = field(default_factory=list)  # (time, markers in the array)
    events: dict[int, float] = field(default_factory=dict)
    lock: threading.Condition = field(default_factory=threading.Condition)

    def start(self) -> None:
        """Subscribe (needs an initialized rospy node)."""
        import rosmc.msg as wire
        import rospy
        from visualization_msgs.msg import InteractiveMarkerUpdate, MarkerArray

        rospy.Subscriber(
            "/rosmc/mission_events", wire.MissionEvent, self._on_event, queue_size=1000
        )
        rospy.Subscriber(
            "/rosmc/markers/update", InteractiveMarkerUpdate, self._on_update, queue_size=1000
        )
        rospy.Subscriber("/rosmc/markers/icons", MarkerArray, self._on_icons, queue_size=1000)

    def _on_event(self, msg: Any) -> None:
        with self.lock:
            self.events[msg.revision] = time.monotonic()
            self.lock.notify_all()

    def _on_update(self, msg: Any) -> None:
        now = time.monotonic()
        if not (msg.markers or msg.poses or msg.erases):
            return  # keep-alive
        update = Update(
            now,
            tuple(m.name for m in msg.markers),
            tuple(p.name for p in msg.poses),
            tuple(msg.erases),
        )
        with self.lock:
            self.updates.append(update)
            self.lock.notify_all()

    def _on_icons(self, msg: Any) -> None:
        with self.lock:
            self.icons.append((time.monotonic(), len(msg.markers)))

    def event_time(self, revision: int, timeout: float = 10.0) -> float:
        """When the event of ``revision`` arrived here (waits for it)."""
        deadline = time.monotonic() + timeout
        with self.lock:
            while revision not in self.events:
                left = deadline - time.monotonic()
                if left <= 0:
                    raise RuntimeError(f"no event {revision}")
                self.lock.wait(left)
            return self.events[revision]

    def first_carrying(self, names: set[str], since: float, timeout: float = 10.0) -> float:
        """When the first update after ``since`` that carries one of ``names`` arrived."""
        deadline = time.monotonic() + timeout
        with self.lock:
            while True:
                for update in self.updates:
                    if update.at >= since and names & {
                        *update.markers,
                        *update.poses,
                        *update.erases,
                    }:
                        return update.at
                left = deadline - time.monotonic()
                if left <= 0:
                    raise RuntimeError(f"no update of {sorted(names)}")
                self.lock.wait(left)

    def between(self, start: float, end: float) -> list[Update]:
        """The updates that arrived from ``start`` to ``end``."""
        with self.lock:
            return [u for u in self.updates if start <= u.at <= end]

    def icon_markers_between(self, start: float, end: float) -> tuple[int, int]:
        """Icon arrays and the icon markers they held, from ``start`` to ``end``."""
        with self.lock:
            got = [n for at, n in self.icons if start <= at <= end]
        return len(got), sum(got)


def team_motion(robots: list[str], stop: threading.Event, hz: float = 10.0) -> None:
    """TF and telemetry of ``robots`` at ``hz``, as the simulator sends them (until ``stop``)."""
    import rosmc.msg as wire
    import rospy
    from geometry_msgs.msg import TransformStamped
    from tf2_msgs.msg import TFMessage

    telemetry = [
        rospy.Publisher(f"/{robot}/telemetry", wire.Telemetry, queue_size=10) for robot in robots
    ]
    tf = rospy.Publisher("/tf", TFMessage, queue_size=100)
    tick = 0
    while not stop.wait(1.0 / hz):
        tick += 1
        now = rospy.Time.now()
        transforms = []
        for i, (robot, pub) in enumerate(zip(robots, telemetry, strict=True)):
            angle = tick * 0.05 + i
            x, y = 10 * math.cos(angle), 10 * math.sin(angle)
            msg = wire.Telemetry(
                agent=robot,
                stamp=now,
                frame_id="map",
                battery=0.5 + 0.4 * math.sin(angle),
                wifi_signal=-60 + 10 * math.cos(angle),
                in_coverage=True,
            )
            msg.pose.x, msg.pose.y, msg.pose.yaw = x, y, angle
            pub.publish(msg)
            transform = TransformStamped()
            transform.header.stamp = now
            transform.header.frame_id = "map"
            transform.child_frame_id = f"{robot}/base_link"
            transform.transform.translation.x = x
            transform.transform.translation.y = y
            transform.transform.rotation.z = math.sin(angle / 2)
            transform.transform.rotation.w = math.cos(angle / 2)
            transforms.append(transform)
        tf.publish(TFMessage(transforms=transforms))


class FakeRobot:
    """One robot's end of its link: acknowledges every upload, reports statuses on request."""

    def __init__(self, agent: str) -> None:
        import rosmc.msg as wire
        import rospy

        from rosmc_server import interface

        self.agent = agent
        self.queue: list[str] = []  # the synchronized queue it holds, in order
        self._seq = 0
        self._last: Any = None
        self._wire = wire
        topics = interface.ground_link(agent)
        self._ack = rospy.Publisher(topics.ack, wire.RobotAck, queue_size=100)
        self._report = rospy.Publisher(topics.report, wire.RobotReport, queue_size=100)
        self._snapshot = rospy.Publisher(topics.snapshot, wire.ExecutorSnapshot, queue_size=10)
        self._commands = rospy.Subscriber(topics.command, wire.RobotCommand, self._on_command)

    def connected(self) -> bool:
        """Whether the server hears each of its topics."""
        return all(
            p.get_num_connections() > 0 for p in (self._ack, self._report, self._snapshot)
        ) and (self._commands.get_num_connections() > 0)

    def hello(self) -> None:
        """Send an empty snapshot, so that the server learns the report numbering."""
        from rosmc_server.core.robots.link import queue_hash

        self._snapshot.publish(
            self._wire.ExecutorSnapshot(agent=self.agent, queue_hash=queue_hash([]), state="idle")
        )

    def _on_command(self, msg: Any) -> None:
        from rosmc_server.core.robots.link import queue_hash

        ids = [skill.id for skill in msg.skills]
        if msg.type == self._wire.RobotCommand.UPLOAD:
            self.queue += [i for i in ids if i not in self.queue]
        self._ack.publish(
            self._wire.RobotAck(
                agent=self.agent, seq=msg.seq, accepted_ids=ids, queue_hash=queue_hash(self.queue)
            )
        )

    def report(self, skill_id: str, status: int) -> None:
        """Report that ``skill_id`` is now ``status``."""
        import rospy

        self._seq += 1
        self._last = self._wire.RobotReport(
            agent=self.agent,
            seq=self._seq,
            stamp=rospy.Time.now(),
            skill_id=skill_id,
            status=self._wire.SkillStatus(status),
            attempt=1,
            started=time.time(),
        )
        self.resend()

    def resend(self) -> None:
        """Send the last report again (the server drops one that overtakes an upload's ack)."""
        self._report.publish(self._last)
