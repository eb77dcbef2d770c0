"""The mission executor node of one robot: ``/<robot>/mission_executor``.

Subscribes:
    ``<link>/command`` (rosmc/RobotCommand), ``<link>/report_ack`` (rosmc/ReportAck).
Publishes:
    ``<link>/ack`` (rosmc/RobotAck), ``<link>/report`` (rosmc/RobotReport, retransmitted
    until acknowledged), ``<link>/snapshot`` (rosmc/ExecutorSnapshot, every
    ``~snapshot_period`` while anything in it changes, else every
    ``~idle_snapshot_period`` but twice within the ground's link timeout
    (:mod:`..core.pacing`); the whole queue in the first and when the ground asks,
    its digest always), ``/rosmc/barriers`` (rosmc/BarrierSignal, a copy for observers).
Radio side channel (UDP, :mod:`rosmc_server.common.ros.radio`, registered as
    ``/rosmc/radio/<robot>``): barrier signals to and from the other robots, and beacons
    to and from the ground (:class:`~rosmc_server.core.robots.radio.BeaconPlan`: seldom while it
    hears the ground); a ground beacon after a silence reconnects the link's topics.

``<link>`` is ``/rosmc/link/<robot>`` (talking to the ground directly) or, with
``~robot_side:=true``, ``/<robot>/link`` (behind a link emulator).

Parameters (private):
    ``~agent`` (str, required): the robot's agent name in the mission.
    ``~skills`` (str): ``module:function`` returning the robot's SkillTypes
        (default: the basic skills, ``rosmc_server.executor.basic_skills:skill_types``).
    ``~state_file`` (str): where the executor keeps its state across restarts
        (default ``$ROS_HOME/rosmc/<agent>_executor.json``; "" = keep nothing).
    ``~library`` (str): the skill library (YAML) this robot's skills must fit; it declares
        their parameters and may bind skills to ROS actions, services and topics (default:
        the skills module's ``library(agent)`` if it has one, else none: nothing checked).
    ``~pose_source`` (str): ``module:function`` returning the robot's pose source (where it
        is, remembered at each ground contact for the ``return_to_link`` policy); default:
        the skills module's ``pose_source`` if it has one, else none.
    ``~snapshot_period`` (float, s, 1.0), ``~idle_snapshot_period`` (float, s, 5.0),
    ``~report_retry`` (float, s, 0.5),
    ``~tick_rate`` (float, Hz, 50), ``~robot_side`` (bool, false).
    ``~radio_key`` (str): the deployment's radio key file, which signs the radio side
        channel's datagrams (default ``$ROS_HOME/rosmc/radio.key``, made there if missing;
        a key given here must exist: see :mod:`rosmc_server.core.robots.radio_key`).
    ``~cwd`` (str): a relative ``~state_file`` is taken from there (launch files pass the
    directory roslaunch was typed in).

    They are read once at start and deleted, so a later executor of the same name starts
    from its own settings, never from a previous run's.
"""

from __future__ import annotations

import argparse
import contextlib
import importlib
import logging
import sys
import threading
import time
from collections.abc import Iterable, Iterator, Sequence
from pathlib import Path
from typing import cast

import rosmc.msg as wire
import rospy

from rosmc_server import interface
from rosmc_server.common.ros.graph_join import join_graph
from rosmc_server.common.ros.logging_bridge import bridge_logging_to_rosout
from rosmc_server.common.ros.station import launch_path

from ...common.ros.radio import (
    GROUND,
    Radio,
    TopicListener,
    node_radio_key,
    reconnect_in_background,
)
from ...conversions.robot_link import (
    ack_to_msg,
    command_from_msg,
    report_to_msg,
    signal_from_msg,
    signal_to_msg,
    snapshot_to_msg,
)
from ...core import LibraryError, RosmcError, SkillSetupError
from ...core.errors import RadioKeyError
from ...core.robots.drop_log import DropLog
from ...core.robots.radio import BeaconPlan, ContactWatch
from ...core.robots.radio_key import RadioKey
from ..core import Command, Engine, Report, Signal, SkillType
from ..core.lost_link import PoseSource, no_pose
from ..core.pacing import SnapshotPacer
from ..core.state_file import load_state, save_state
from .config import ExecutorConfig
from .skill_setup import default_library, robot_skill_types

_log = logging.getLogger(__name__)


def load_skill_types(spec: str, agent: str) -> dict[str, SkillType]:
    """Import ``module:function`` and call it with the agent name for its skill types."""
    module_name, _, function = spec.partition(":")
    factory = getattr(importlib.import_module(module_name), function or "skill_types")
    types: Iterable[SkillType] = factory(agent)
    return {kind.name: kind for kind in types}


def load_pose_source(spec: str, skills: str, agent: str) -> PoseSource:
    """The robot's pose source: ``spec`` (``module:function``), else the skills module's."""
    if not spec:
        module = importlib.import_module(skills.partition(":")[0])
        factory = getattr(module, "pose_source", None)
        return no_pose if factory is None else cast(PoseSource, factory(agent))
    module_name, _, function = spec.partition(":")
    factory = getattr(importlib.import_module(module_name), function or "pose_source")
    return cast(PoseSource, factory(agent))


class ExecutorNode:
    """Wires an :class:`Engine` to the robot link and the barrier topic."""

    def __init__(
        self,
        agent: str,
        skill_types: dict[str, SkillType],
        state_file: Path | None,
        robot_side: bool = False,
        pose_source: PoseSource = no_pose,
        *,
        radio_key: RadioKey,
    ) -> None:
        self.agent = agent
        self._lock = threading.RLock()
        self._state_file = state_file
        self._dirty = False
        # Reports made while a command is answered or the engine ticks: they go out after
        # the state is persisted (and the command's ack).
        self._held_reports: list[Report] | None = None
        self._echo: tuple[float, float] | None = None  # newest stamped report ack: sent, heard
        # The whole queue goes in the first snapshot and again whenever the ground asks
        # (a new ground, or one whose statuses disagree with the digest).
        self._full_snapshot = True
        self.pacer = SnapshotPacer()
        topics = interface.robot_link(agent) if robot_side else interface.ground_link(agent)
        self._ack_pub = rospy.Publisher(topics.ack, wire.RobotAck, queue_size=100)
        self._report_pub = rospy.Publisher(topics.report, wire.RobotReport, queue_size=1000)
        self._snapshot_pub = rospy.Publisher(topics.snapshot, wire.ExecutorSnapshot, queue_size=5)
        self._barrier_pub = rospy.Publisher(
            interface.BARRIER_TOPIC, wire.BarrierSignal, queue_size=100
        )
        # Mission time is ROS time (sim time in simulation); ground contact is measured
        # in wall seconds, as the ground measures the robot's silence.
        self.engine = Engine(
            agent,
            skill_types,
            rospy.get_time,
            self,
            pose_source,
            pace_clock=time.monotonic,
            link_clock=time.monotonic,
        )
        if state_file is not None and state_file.exists():
            try:
                interrupted = load_state(self.engine, state_file)
            except (ValueError, KeyError, OSError) as error:
                _log.error("%s: ignoring unreadable executor state: %s", agent, error)
            else:
                _log.info(
                    "%s: restored %d queued skills from %s (interrupted: %s)",
                    agent,
                    len(self.engine.ledger.queue),
                    state_file,
                    ", ".join(interrupted) or "none",
                )
        self._listeners = [
            TopicListener(topics.command, wire.RobotCommand, self._on_command, queue_size=100),
            TopicListener(topics.report_ack, wire.ReportAck, self._on_report_ack, queue_size=100),
        ]
        self._contact = ContactWatch()
        self._beacons = BeaconPlan()
        self._drop_lock = threading.Lock()
        self._dropped_commands = DropLog("command")
        self._dropped_signals = DropLog("barrier signal")
        self.radio = Radio(agent, self._on_beacon, self._on_signal, key=radio_key)

    # -- engine outputs (called with the lock held) ------------------------------------
    def report(self, report: Report) -> None:
        """Publish a new report (it is retransmitted until acknowledged); inside
        :meth:`_durable_step`, once the state is persisted."""
        if self._held_reports is not None:
            self._held_reports.append(report)
            return
        self._report_pub.publish(report_to_msg(self.agent, report))

    def signal(self, signal: Signal) -> None:
        """Send a barrier signal to the peers over the radio (and publish it for observers)."""
        msg = signal_to_msg(signal)
        self.radio.refresh()  # a peer may have moved since the directory was last read
        self.radio.signal(msg, self.radio.robots())
        self._barrier_pub.publish(msg)

    def changed(self) -> None:
        """Persist soon."""
        self._dirty = True

    # -- inputs ------------------------------------------------------------------------
    def _on_command(self, msg: wire.RobotCommand) -> None:
        if msg.agent != self.agent:
            self._dropped(self._dropped_commands, "it is for another robot", f"for {msg.agent!r}")
            return
        command: Command | None = None
        reason = ""
        try:
            command = command_from_msg(msg)
        except (ValueError, RosmcError) as error:  # refused below, so the link goes on
            _log.warning("%s: refusing malformed command %d: %s", self.agent, msg.seq, error)
            reason = f"the robot cannot read command {msg.seq}: {error}"
        with self._lock, self._durable_step():
            if command is None:
                ack = self.engine.refuse_command(msg.seq, reason)
            else:
                ack = self.engine.handle_command(command)
            self._persist()  # before answering: an acknowledged command survives a crash
            # The ground learns from the ack that an uploaded skill is on the robot; a
            # report about that skill (it may start at once) must not overtake it.
            if ack is not None:
                self._ack_pub.publish(ack_to_msg(self.agent, ack, rospy.get_time()))

    def _on_report_ack(self, msg: wire.ReportAck) -> None:
        if msg.agent == self.agent:
            with self._lock:
                self.engine.report_acknowledged(msg.seq)
                self._full_snapshot |= msg.want_full
                if msg.link_timeout > 0.0:
                    self.pacer.ground_timeout = float(msg.link_timeout)
                if msg.sent > 0.0:  # echoed in the next snapshot: the ground's round trip
                    self._echo = (msg.sent, time.monotonic())

    def _snapshot_msg(self, now: float) -> wire.ExecutorSnapshot | None:
        """The snapshot due at ``now``, or None (see :class:`SnapshotPacer`).

        Most snapshots leave the queue out (its digest stands in): listing every skill
        held, every second, would take much of a radio's bandwidth.
        """
        snapshot = self.pacer.due(self.engine.snapshot(full=self._full_snapshot), now)
        if snapshot is None:
            return None
        msg = snapshot_to_msg(self.agent, snapshot)
        msg.radio_dropped = self.radio.dropped
        self._full_snapshot = False
        if self._echo is not None:
            sent, received = self._echo
            msg.echo_sent, msg.echo_held = sent, time.monotonic() - received
        return msg

    def _on_beacon(self, sender: str, returning: bool) -> None:
        if sender != GROUND:
            return
        now = time.monotonic()
        # (Read by the loop's thread without a lock: a stale read delays a beacon a tick.)
        self._beacons.heard(now)
        if self._contact.heard(GROUND, now):
            # The ground is back after a silence: its stalled connections would resume
            # only at TCP's next retransmission, which backs off to minutes.
            reconnect_in_background(self._listeners, f"{self.agent} hears the ground again")

    def _on_signal(self, msg: wire.BarrierSignal) -> None:
        try:
            signal = signal_from_msg(msg)
        except ValueError as error:
            self._dropped(self._dropped_signals, "it cannot be read", f"from {msg.agent}: {error}")
            return
        with self._lock, self._durable_step():
            self.engine.hear(signal)

    def _dropped(self, log: DropLog, reason: str, detail: str) -> None:
        """Count a dropped input; warn at a limited rate (a flood must not flood the log)."""
        with self._drop_lock:
            warning = log.drop(reason, detail, time.monotonic())
        if warning is not None:
            _log.warning("%s: %s", self.agent, warning)

    # -- the loop ------------------------------------------------------------------------
    def spin(self, tick_rate: float, report_retry: float) -> None:
        """Tick the engine, retransmit reports and publish snapshots (paced by
        :attr:`pacer`) until shutdown."""
        next_snapshot = next_retry = 0.0
        period = 1.0 / tick_rate
        while not rospy.is_shutdown():
            now = time.monotonic()
            beacon = self._beacons.due(now)
            if beacon is not None:
                self.radio.beacon(GROUND, beacon)
            with self._lock:
                with self._durable_step():
                    try:
                        self.engine.tick()
                    except Exception:  # keep the robot's executor alive whatever a skill does
                        _log.exception("%s: executor tick failed", self.agent)
                if now >= next_retry:
                    next_retry = now + report_retry
                    for report in self.engine.ledger.unacked:
                        self._report_pub.publish(report_to_msg(self.agent, report))
                if now >= next_snapshot:
                    snapshot = self._snapshot_msg(now)
                    if snapshot is not None:
                        self._snapshot_pub.publish(snapshot)
                    next_snapshot = self.pacer.next_check(now)
                self._persist()
            time.sleep(max(0.0, period - (time.monotonic() - now)))
        self.radio.close()

    @contextlib.contextmanager
    def _durable_step(self) -> Iterator[None]:
        """Hold the reports the engine makes inside; persist, then publish them.

        A report leaves only once what it says is on disk: a robot killed right after
        reporting a skill's end must not run that skill again. Called with the lock held.
        """
        self._held_reports = []
        try:
            yield
        finally:
            self._persist()
            held, self._held_reports = self._held_reports, None
            for report in held:
                self._report_pub.publish(report_to_msg(self.agent, report))

    def _persist(self) -> None:
        if self._dirty and self._state_file is not None:
            save_state(self.engine, self._state_file)
        self._dirty = False


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of ``mission_executor``."""
    args = rospy.myargv(list(argv) if argv is not None else sys.argv)
    parser = argparse.ArgumentParser(
        prog="mission_executor",
        description="ROSMC on-robot mission executor. Settings are private parameters "
        "(_agent:=NAME, _skills:=module:function, _state_file:=PATH).",
    )
    parser.parse_args(args[1:])
    join_graph("mission_executor")
    bridge_logging_to_rosout()
    config = ExecutorConfig.from_params()
    if not config.agent:
        _log.critical("mission executor: set ~agent to the robot's agent name")
        return 2
    try:
        skill_types = load_skill_types(config.skills, config.agent)
        pose_source = load_pose_source(config.pose_source, config.skills, config.agent)
        library = config.library or default_library(config.skills, config.agent)
    except (ImportError, AttributeError, ValueError) as error:
        _log.critical("mission executor %s: cannot load skills: %s", config.agent, error)
        return 1
    try:
        skill_types = robot_skill_types(
            config.agent, skill_types, launch_path(library) if library else None
        )
        radio_key = node_radio_key(config.radio_key, f"mission executor {config.agent}")
    except (LibraryError, SkillSetupError, RadioKeyError) as error:
        _log.critical("mission executor %s: %s", config.agent, error)
        return 1
    node = ExecutorNode(
        config.agent,
        skill_types,
        config.state_file,
        config.robot_side,
        pose_source,
        radio_key=radio_key,
    )
    _log.info(
        "%s: mission executor ready with skills %s (%s link)",
        config.agent,
        ", ".join(sorted(skill_types)),
        "robot-side" if config.robot_side else "direct",
    )
    node.pacer.period = config.snapshot_period
    node.pacer.idle_period = config.idle_snapshot_period
    node.spin(config.tick_rate, config.report_retry)
    return 0
