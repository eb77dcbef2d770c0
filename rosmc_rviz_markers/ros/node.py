"""The marker node ``/rosmc/markers``: the mission in rviz, kept current event by event.

Follows the mission with a :class:`~rosmc_server.ros.client.MissionFollower` and shows it
with one ``interactive_markers`` server; every mirror update touches only the markers it
changed (one staged batch, one ``applyChanges()``). Clicks, drags and the stock rviz tools
become mission server calls (see :mod:`.interaction`).

ROS interface (every name behind ``~ns``):
    Publishes ``/rosmc/markers/update`` (visualization_msgs/InteractiveMarkerUpdate),
    ``/rosmc/markers/update_full`` (InteractiveMarkerInit, latched),
    ``/rosmc/markers/icons`` (visualization_msgs/MarkerArray: status icons, and a text
    above the origin once the mission server restarted, naming its revision; all of them
    to a subscriber as it connects, then only what changed, see :mod:`.icon_layer`),
    ``/rosmc/selection`` (rosmc/Selection, latched: what the operator clicked),
    ``/rosmc/markers/clock`` (visualization_msgs/MarkerArray, latched: the mission clock)
    and the ``station`` interactive marker (its menu opens the command window), see
    :mod:`.station_layer`,
    ``/rosmc/coverage`` (visualization_msgs/MarkerArray, latched: radio coverage, see
    :mod:`.coverage_layer`, which also subscribes ``/rosmc/sim/coverage``).
    Subscribes ``/rosmc/markers/feedback`` (InteractiveMarkerFeedback), ``/rosmc/selection``,
    ``/rosmc/markers/new_position`` (geometry_msgs/PointStamped, Publish Point tool),
    ``/rosmc/markers/new_pose`` (PoseStamped, 2D Nav Goal tool),
    ``/rosmc/markers/new_area`` (PoseWithCovarianceStamped, 2D Pose Estimate tool),
    and, through the follower, ``/rosmc/mission_events`` and ``/rosmc/agent_states``.
    Calls the operator services ``/rosmc/*`` (``get_library``, ``get_mission``, mutations).
    Parameters: ``~ns`` (""; ``/replay`` follows a replay), ``~read_only`` (default: ns set),
    ``~follow_tf`` (default: ns empty), ``~library`` (a library file to use instead of
    the one the followed server or replay serves), ``~commit_delay`` (0.5 s).
"""

from __future__ import annotations

import logging
import sys
import threading
import time
from collections.abc import Mapping, Sequence

import rospy
from visualization_msgs.msg import Marker

from rosmc_server.common.ros.graph_join import join_graph
from rosmc_server.common.ros.logging_bridge import bridge_logging_to_rosout
from rosmc_server.core import AgentStatus, Library, MissionState, load_library
from rosmc_server.core.live.mirror import MissionMirror
from rosmc_server.core.live.updates import MirrorUpdate, MissionReset
from rosmc_server.core.views.geometry import Point
from rosmc_server.interface import MAP_FRAME, base_link
from rosmc_server.ros.client import MissionFollower, Outcome

from .. import topics
from ..core.icons import WARN, IconRow, icon_levels, status_rows
from ..core.scene import Scene, Touched
from ..core.specs import MarkerSpec
from .adapter import MarkerServer
from .config import MarkerNodeConfig
from .convert import icon_markers, interactive_marker_msg, pose_msg
from .coverage_layer import CoverageLayer
from .icon_layer import IconLayer
from .interaction import Interaction
from .station_layer import STATION_MARKER, StationLayer
from .tf_presence import TfPresence

_log = logging.getLogger(__name__)
SERVER_ICON = "mission_server"  # the status text of the server itself (icons/mission_server)
SERVER_NOTE_AT = (0.0, 0.0, 9.3)  # + ICON_BASE: over the lander, above its score and clock
SERVER_NOTE_TEXT = 0.8  # letter height (m): as large as the site's region labels


class MarkerNode:
    """Interactive markers for the followed mission (see the module docstring)."""

    def __init__(self, config: MarkerNodeConfig) -> None:
        self.config = config
        self.follower = MissionFollower(
            prefix=config.ns,
            on_restart=self._on_server_restart,
            on_journal_alert=self._on_journal_alert,
        )
        self._server_note = ""  # said in rviz above the origin: the server restarted
        self._journal_note = ""  # and what its journal alerts (a full disk)
        self._lock = threading.Lock()  # published specs, groups and the server
        self._published: dict[str, MarkerSpec] = {}
        self._groups: dict[str, set[str]] = {}  # task marker -> its interactive markers
        self._scene: Scene | None = None
        self._pending = Touched()
        self._wake = threading.Condition()
        self._closed = False
        self._unsubscribe: list[object] = []
        self.server = MarkerServer(topics.topic(topics.MARKERS_NS, config.ns), self._on_feedback)
        self._icons = IconLayer(topics.topic(topics.ICONS_TOPIC, config.ns))
        self.interaction = Interaction(self, config)
        self.coverage = CoverageLayer(config.ns)  # radio coverage and last-link marks
        # the mission clock over the lander, whose menu opens the command window
        self.station = StationLayer(self.server, self._lock, config.ns, menu=not config.read_only)
        self._tf: TfPresence | None = None  # which agents have TF (follow_tf only)
        self._worker = threading.Thread(target=self._run, name="rosmc-markers", daemon=True)

    # -- what the interaction layer reads ---------------------------------------------------------
    @property
    def mirror(self) -> MissionMirror:
        """The live mission copy."""
        return self.follower.mirror

    @property
    def scene(self) -> Scene | None:
        """The scene (None until the library arrived)."""
        return self._scene

    def published(self, name: str) -> MarkerSpec | None:
        """The spec last published under interactive marker ``name``."""
        with self._lock:
            return self._published.get(name)

    def snap_back(self, name: str) -> None:
        """Publish marker ``name`` again as the mission has it (undo what rviz shows)."""
        with self._lock:
            spec = self._published.get(name)
            if spec is not None:
                self.server.insert(interactive_marker_msg(spec))
                self.server.apply()

    def mark(self, touched: Touched) -> None:
        """Queue markers to refresh (any thread; the worker publishes them)."""
        with self._wake:
            self._pending.everything |= touched.everything
            self._pending.markers |= touched.markers
            self._pending.agents |= touched.agents
            self._pending.icons |= touched.icons
            self._wake.notify()

    # -- lifecycle --------------------------------------------------------------------------------
    def start(self) -> None:
        """Fetch the library, follow the mission and start publishing."""
        self._worker.start()
        self.station.start()
        self.follower.start()
        if self.config.library:
            self._take_library(load_library(self.config.library))
        else:  # the server's, or a replay's: the library the recording ran with
            self.follower.library(self._on_library)

    def close(self) -> None:
        """Stop following and publishing."""
        with self._wake:
            self._closed = True
            self._wake.notify()
        self.interaction.close()
        self.station.close()
        self.follower.close()
        if self._tf is not None:
            self._tf.close()

    def _on_library(self, outcome: Outcome[Library]) -> None:
        if outcome.value is None:
            _log.warning("cannot fetch the skill library (%s); trying again", outcome.error)
            timer = threading.Timer(2.0, lambda: self.follower.library(self._on_library))
            timer.daemon = True
            timer.start()
            return
        self._take_library(outcome.value)

    def _take_library(self, library: Library) -> None:
        old = self._scene
        if old is not None and old.library == library:
            return  # a restarted server with the same library
        scene = Scene(library, read_only=self.config.read_only, follow_tf=self.config.follow_tf)
        if self._tf is not None:
            scene.set_tf_missing(self._tf.last)
        self._scene = scene
        if old is None:
            self._unsubscribe.append(self.mirror.subscribe(self._on_update))
        else:  # another library: the old agents' markers go, everything is drawn anew
            self._forget_published()
            self.mark(Touched(everything=True))
        if self.config.follow_tf and self._tf is None:
            self._tf = TfPresence(self._agents, self._on_tf_missing)
        _log.info("markers for library '%s' (%d agents)", library.name, len(library.agents))

    def _forget_published(self) -> None:
        with self._lock:
            for name in self._published:
                self.server.erase(name)
            self._published.clear()
            self._groups.clear()
            self.server.apply()

    def _agents(self) -> list[str]:
        scene = self._scene
        return scene.agents() if scene is not None else []

    def _on_tf_missing(self, agents: frozenset[str]) -> None:
        scene = self._scene
        if scene is not None:
            self.mark(scene.set_tf_missing(agents))

    def _on_server_restart(self, revision: int) -> None:
        self._server_note = (
            f"mission server restarted {time.strftime('%H:%M:%S')} from revision {revision}"
        )
        _log.warning("%s", self._server_note)
        self.mark(Touched(icons={SERVER_ICON}))
        if not self.config.library:  # it may run with another library: follow it
            self.interaction.forget_library()
            self.follower.library(self._on_library, fresh=True)

    def _on_journal_alert(self, alert: str) -> None:
        self._journal_note = f"journal: {alert}" if alert else ""
        self.mark(Touched(icons={SERVER_ICON}))

    def _on_update(self, update: MirrorUpdate) -> None:
        # Called with the mirror lock held: only note what changed; the worker does the rest.
        scene = self._scene
        if any(isinstance(change, MissionReset) for change in update.changes):
            self.interaction.on_reset(update.revision)
        if scene is not None:
            touched = scene.touched(update)
            if touched:
                self.mark(touched)

    # -- the worker: specs, staging, one applyChanges per batch -----------------------------------
    def _run(self) -> None:
        while True:
            with self._wake:
                while not self._pending and not self._closed:
                    self._wake.wait()
                if self._closed:
                    return
                touched, self._pending = self._pending, Touched()
            try:
                self._refresh(touched)
            except Exception:  # one bad update must not stop the markers for good
                _log.exception("cannot refresh the markers")

    def _refresh(self, touched: Touched) -> None:
        scene = self._scene
        if scene is None:
            return
        with self.mirror.lock:
            state = self.mirror.state
            if state is None:
                return
            statuses = self.mirror.agent_statuses
            names = set(touched.markers)
            # Agents touched under a previous library may be unknown to this one (the server
            # restarted with another library): they have nothing left to draw.
            agents = set(touched.agents) & set(scene.agents())
            boxes = scene.label_boxes
            if touched.everything or touched.markers:
                # task labels depend on task markers alone: a robot's status costs none
                names |= scene.relayout(state, None if touched.everything else touched.markers)
            if touched.everything:
                names |= {m.name for m in state.markers}
                with self._lock:
                    names |= set(self._groups)
                agents = set(scene.agents())
            specs = {name: scene.marker_specs(state, name) for name in names}
            agent_specs = [scene.agent_spec(a, state, statuses.get(a)) for a in agents]
            icons: list[Marker] | None = None
            # status blocks keep clear of the task labels: they follow when a label moves
            if touched.everything or touched.icons or scene.label_boxes != boxes:
                icons = self._icon_markers(scene, statuses, state)
        with self._lock:
            for spec in agent_specs:
                self._stage(spec)
            for name, group in specs.items():
                new_names = {spec.name for spec in group}
                for gone in self._groups.get(name, set()) - new_names:
                    self.server.erase(gone)
                    self._published.pop(gone, None)
                for spec in group:
                    self._stage(spec)
                if new_names:
                    self._groups[name] = new_names
                else:
                    self._groups.pop(name, None)
            self.server.apply()
        if icons is not None:
            self._icons.show(icons)

    def _stage(self, spec: MarkerSpec) -> None:
        old = self._published.get(spec.name)
        if old == spec:
            return
        if old is not None and old.same_but_pose(spec):
            self.server.set_pose(spec.name, pose_msg(spec.position, spec.yaw), spec.frame)
        else:
            self.server.insert(interactive_marker_msg(spec))
        self._published[spec.name] = spec

    @staticmethod
    def _blocks(
        scene: Scene, statuses: Mapping[str, AgentStatus], state: MissionState
    ) -> list[tuple[str, tuple[IconRow, IconRow], Point | None, int]]:
        """Every robot's status block: agent, rows, map position (None: unknown), level."""
        agents = scene.library.dynamic_agents
        poses = {agent: statuses[agent].pose if agent in statuses else None for agent in agents}
        points = {a: (p.x, p.y, p.z) if p else None for a, p in poses.items()}
        rows = {}
        for agent in agents:
            status = statuses.get(agent)
            label = ""
            if (
                status is not None
                and status.current_skill
                and state.has_skill(status.current_skill)
            ):
                label = state.skill(status.current_skill).label
            rows[agent] = status_rows(status, label, agent)
        texts = {a: [row.text for row in r] for a, r in rows.items()}
        levels = icon_levels(points, texts, scene.label_boxes)
        return [(agent, rows[agent], points[agent], levels[agent]) for agent in agents]

    def _icon_markers(
        self, scene: Scene, statuses: Mapping[str, AgentStatus], state: MissionState
    ) -> list[Marker]:
        out: list[Marker] = []
        for index, (agent, rows, point, level) in enumerate(self._blocks(scene, statuses, state)):
            frame, position = base_link(agent), (0.0, 0.0, 0.0)
            if not self.config.follow_tf or agent in scene.tf_missing:
                frame = MAP_FRAME
                position = point or scene.agent_spec(agent, state, statuses.get(agent)).position
            out += icon_markers(agent, rows, frame, position, index * 10, level)
        said = (self._server_note, self._journal_note)
        notes = tuple(IconRow("server", text, WARN) for text in said if text)
        if notes:
            for marker in icon_markers(SERVER_ICON, notes, MAP_FRAME, SERVER_NOTE_AT, 0):
                marker.scale.z = SERVER_NOTE_TEXT
                out.append(marker)
        return out

    # -- feedback ---------------------------------------------------------------------------------
    def _on_feedback(self, feedback: object) -> None:
        if getattr(feedback, "marker_name", "") == STATION_MARKER:
            self.station.on_feedback(feedback)
        else:
            self.interaction.on_feedback(feedback)


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of ``markers_node``."""
    rospy.myargv(argv if argv is not None else sys.argv)
    join_graph("markers", anonymous=False)
    bridge_logging_to_rosout()
    node = MarkerNode(MarkerNodeConfig.from_params())
    node.start()
    _log.info("marker node ready")
    rospy.spin()
    node.close()
    return 0
