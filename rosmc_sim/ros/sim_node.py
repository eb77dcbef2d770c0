"""The simulator node ``/rosmc/sim``: the pybullet site, stepped in sim time, on ROS.

It is the clock source: it steps the :class:`Simulation` paced against the
wall clock by ``~real_time_factor`` and publishes the sim time on ``/clock``
after every step (other nodes run with ``/use_sim_time`` true).

Topics (names in :mod:`rosmc_sim.ros.topics`; stamps are sim time):

* ``/clock`` (rosgraph_msgs/Clock): every step;
* per robot, ``/<robot>/sim/skill_run`` (rosmc/SkillRun, subscribed) and
  ``/<robot>/sim/skill_run_status`` (rosmc/SkillRunStatus, latched): the skill-run
  protocol (:mod:`rosmc_sim.ros.skill_run_channel`);
* ``/tf``, ``/<robot>/odom`` (nav_msgs/Odometry), ``/<robot>/telemetry``
  (rosmc/Telemetry), ``/<robot>/link/blackout`` (std_msgs/Bool, latched)
  (:mod:`rosmc_sim.ros.robot_state`);
* ``/rosmc/sim/science`` (rosmc/ScienceState, latched) (:mod:`rosmc_sim.ros.science`);
* ``/rosmc/sim/world`` (visualization_msgs/MarkerArray, latched)
  (:mod:`rosmc_sim.ros.world_markers`);
* ``/rosmc/sim/coverage`` (rosmc/CoverageGrid, latched): the radio model over the site,
  anew when a Wi-Fi box moves (:mod:`rosmc_sim.ros.coverage_publisher`);
* ``/rosmc/site`` (rosmc/SiteMap, latched, once): the site the mission server checks skill
  targets against (:mod:`rosmc_sim.ros.site_publisher`).

Private parameters: ``~scenario`` (path, relative ones resolved against the
``rosmc_sim`` package; default ``rosmc_sim/scenarios/mars_sample_return.yaml``),
``~real_time_factor`` (float, 1.0; 0 runs as fast as possible), ``~step``
(sim seconds per step, 0.05), ``~clock_rate`` (Hz of wall time, 1000: how often at most
``/clock`` is published, as Gazebo's ``pub_clock_frequency``; 0 publishes every step),
``~gui`` (bool, false: pybullet GUI instead of DIRECT), ``~seed`` (int, 0: where the
stones lie), ``~cwd`` (a relative ``~scenario`` is also looked for there; launch files
pass the directory roslaunch was typed in).
"""

from __future__ import annotations

import argparse
import logging
import os
import signal
import sys
import threading
import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import rospy
import rospy.impl.simtime
import rospy.rostime
from rosgraph_msgs.msg import Clock

from rosmc_server.common.ros.graph_join import join_graph
from rosmc_server.common.ros.logging_bridge import bridge_logging_to_rosout
from rosmc_server.common.ros.station import CWD_PARAM, resolve_against

from ..core.scenario import Scenario, ScenarioError, load_scenario
from ..core.sim import Simulation
from ..core.world import World
from .coverage_publisher import CoveragePublisher
from .robot_state import RobotStatePublisher
from .science import SciencePublisher
from .site_publisher import SitePublisher
from .skill_run_channel import SkillRunChannel
from .skill_run_desk import SkillRunDesk
from .timing import Pacer, Throttle
from .world_markers import WorldPublisher

PACKAGE_DIR = Path(__file__).resolve().parents[1]
DEFAULT_SCENARIO = "rosmc_sim/scenarios/mars_sample_return.yaml"
CLOCK_TOPIC = "/clock"

_log = logging.getLogger(__name__)


class ConfigError(ValueError):
    """A private parameter of the node is invalid."""


@dataclass(frozen=True)
class SimConfig:
    """The node's private parameters."""

    scenario: Path
    real_time_factor: float = 1.0
    step: float = 0.05
    clock_rate: float = 1000.0
    gui: bool = False
    seed: int = 0

    @classmethod
    def from_params(cls) -> SimConfig:
        """Read the private parameters once (see the module docstring)."""
        try:
            config = cls(
                scenario=resolve_scenario(
                    str(rospy.get_param("~scenario", DEFAULT_SCENARIO)),
                    str(rospy.get_param(CWD_PARAM, "")),
                ),
                real_time_factor=float(rospy.get_param("~real_time_factor", 1.0)),
                step=float(rospy.get_param("~step", 0.05)),
                clock_rate=float(rospy.get_param("~clock_rate", 1000.0)),
                gui=bool(rospy.get_param("~gui", False)),
                seed=int(rospy.get_param("~seed", 0)),
            )
        except (TypeError, ValueError) as error:
            raise ConfigError(f"invalid parameter: {error}") from error
        if config.real_time_factor < 0:
            raise ConfigError("~real_time_factor must be 0 (as fast as possible) or positive")
        if not 0 < config.step <= 1.0:
            raise ConfigError("~step must be above 0 and at most 1 s")
        if config.clock_rate < 0:
            raise ConfigError("~clock_rate must be 0 (every step) or positive")
        if config.gui and not os.environ.get("DISPLAY"):
            # pybullet would exit the process from C, without a word to rosout.
            raise ConfigError("~gui needs a display, and DISPLAY is not set")
        return config


def resolve_scenario(path: str, cwd: str = "") -> Path:
    """An absolute scenario path.

    A relative path is looked up in the ``rosmc_sim`` package (``scenarios/x.yaml``), then
    next to it (``rosmc_sim/scenarios/x.yaml``), then in ``cwd`` (where the user launched
    from; "" = the working directory).
    """
    given = Path(path).expanduser()
    if given.is_absolute():
        return given
    here = resolve_against(given, cwd) if cwd else Path.cwd() / given
    candidates = [PACKAGE_DIR / given, PACKAGE_DIR.parent / given, here]
    return next((c for c in candidates if c.is_file()), candidates[0])


class ClockSource:
    """Publishes the sim time on ``/clock``, and keeps this process's rospy time with it.

    With ``/use_sim_time`` set, rospy subscribes every node to ``/clock``, this one
    too; hearing its own clock at every step would cost as much as the simulation.
    So the clock source drops that subscription and sets rospy's time itself (rospy
    has no public API for either; both are guarded).

    Run as fast as possible, the sim steps thousands of times per wall second, more
    than any subscriber can follow; each publish also hands the GIL to rospy's writer
    thread. So ``/clock`` goes out at most ``rate`` times per wall second (0: every
    step), while this process's own time follows every step.
    """

    def __init__(self, rate: float = 0.0) -> None:
        self._publisher = rospy.Publisher(CLOCK_TOPIC, Clock, queue_size=10)
        self._throttle = Throttle(1.0 / rate if rate > 0 else 0.0)
        self.published = 0
        own = getattr(rospy.impl.simtime, "_clock_sub", None)
        self._set_rostime = getattr(rospy.rostime, "_set_rostime", None) if own else None
        if own is not None and self._set_rostime is not None:
            own.unregister()

    def publish(self, sim_time: float, now: float) -> None:
        """Tell rospy here the sim time, and everyone else when due at wall time ``now``."""
        stamp = rospy.Time.from_sec(sim_time)
        if self._throttle.due(now):
            self._publisher.publish(Clock(clock=stamp))
            self.published += 1
        if self._set_rostime is not None:
            self._set_rostime(stamp)


class SimNode:
    """Steps the simulation and runs its ROS adapters (see the module docstring)."""

    def __init__(self, config: SimConfig, scenario: Scenario) -> None:
        self.config = config
        self.world = World(scenario, gui=config.gui)
        self.sim = Simulation(scenario, self.world, seed=config.seed)
        robots = self.sim.robots.values()
        self.channels = [SkillRunChannel(SkillRunDesk(self.sim, r)) for r in robots]
        self.state = RobotStatePublisher(self.sim)
        self.science = SciencePublisher(self.sim)
        self.world_markers = WorldPublisher(self.sim)
        self.site = SitePublisher(self.sim)
        self.coverage = CoveragePublisher(self.sim)
        self._clock = ClockSource(config.clock_rate)
        self.steps = 0

    def step(self) -> None:
        """One step: take requests, advance skill runs and the world, publish what is due."""
        now = time.monotonic()
        for channel in self.channels:
            channel.handle_requests(now)
        for channel in self.channels:
            channel.update(now)
        self.sim.step(self.config.step)
        self.steps += 1
        self._clock.publish(self.sim.time, now)
        self.state.after_step(now)
        self.science.after_step(now)
        self.world_markers.after_step(now)
        self.coverage.after_step(now)

    def run(self, stop: threading.Event) -> None:
        """Step until ``stop`` is set or ROS shuts down, paced by the real-time factor."""
        pacer = Pacer(self.config.real_time_factor)
        cpu0 = time.process_time()
        while not stop.is_set() and not rospy.is_shutdown():
            self.step()
            pacer.wait(self.sim.time)
        _log.info(
            "sim: %.1f s of sim time in %d steps (%d on /clock), real-time factor %.1f, %.2f CPU s",
            self.sim.time,
            self.steps,
            self._clock.published,
            pacer.achieved(self.sim.time),
            time.process_time() - cpu0,
        )

    def close(self) -> None:
        """Cancel running skill runs and disconnect pybullet."""
        for channel in self.channels:
            channel.close()
        self.world.close()


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of ``sim_node``."""
    args = rospy.myargv(list(argv) if argv is not None else sys.argv)
    argparse.ArgumentParser(
        prog="sim_node",
        description="The pybullet simulation of the Mars site (_scenario:=FILE "
        "_real_time_factor:=X _step:=S _clock_rate:=HZ _gui:=BOOL _seed:=N).",
    ).parse_args(args[1:])
    join_graph("sim", disable_signals=True)
    stop = _stop_on_signals()
    bridge_logging_to_rosout()
    try:
        config = SimConfig.from_params()
        scenario = load_scenario(config.scenario)
    except (ConfigError, ScenarioError) as error:
        _log.critical("sim: %s", error)
        rospy.signal_shutdown("no scenario")
        return 1
    return _run(SimNode(config, scenario), stop)


def _stop_on_signals() -> threading.Event:
    """SIGINT and SIGTERM set the returned event.

    rospy's own handler shuts ROS down on the main thread, which deadlocks when the
    signal lands while the sim loop holds a publisher's lock; ours only asks the loop
    to end, and the shutdown follows from ordinary code.
    """
    stop = threading.Event()
    for signum in (signal.SIGINT, signal.SIGTERM):
        signal.signal(signum, lambda _signum, _frame: stop.set())
    return stop


def _run(node: SimNode, stop: threading.Event) -> int:
    _log.info(
        "sim: %s with %s, real-time factor %g",
        node.sim.scenario.name,
        ", ".join(node.sim.robots),
        node.config.real_time_factor,
    )
    try:
        node.run(stop)
    except Exception as error:  # the top-level guard: say what broke, with the traceback
        if isinstance(error, rospy.ROSException) and rospy.is_shutdown():
            return 0  # ROS went away in the middle of a step (rosnode kill, for one)
        _log.exception("sim: stopped by an error")
        return 1
    finally:
        node.close()
        rospy.signal_shutdown("the simulation ended")
    return 0
