"""The site's geometry for rviz: ``/rosmc/sim/world`` (visualization_msgs/MarkerArray, latched).

One array holds everything (after a DELETEALL, so what disappeared goes): the
ground, a pickable ground (a thin, all but invisible slab over the whole site, so that
rviz's Publish Point tool hits something wherever an operator clicks on the site; the
grid is pickable only on its lines), obstacles, slopes (flat, translucent), the lander,
payload boxes, discovered regions (translucent discs with a label east of the disc saying how far
their stones are identified and how many are left: east, so that it never covers the
robots and task markers inside the region), the stones lying in them, the science score and the
stones delivered (a text over the lander), and the Wi-Fi coverage circles of the lander
and of deployed Wi-Fi boxes.
Robot bodies are left to TF and the interactive markers. Namespaces are per
kind; ids are stable (the scenario's order). The array is republished when
what it shows changes (checked every :data:`CHECK_PERIOD` wall seconds, sent
at most every :data:`MIN_PERIOD`), e.g. a box carried, a region discovered.
"""

from __future__ import annotations

import math
from collections.abc import Hashable

import rospy
from geometry_msgs.msg import Point
from std_msgs.msg import ColorRGBA
from visualization_msgs.msg import Marker, MarkerArray

from rosmc_server.core.views.geometry import CHAR_WIDTH
from rosmc_server.core.views.vocabulary import PALETTE, counted
from rosmc_server.interface import MAP_FRAME

from ..core.sim import LEVEL_COLLABORATIVE, LEVEL_SCIENCE, Simulation
from ..core.world import BOX_SIZE, STONE_RADIUS
from .robot_state import yaw_quaternion
from .timing import Throttle
from .topics import WORLD_TOPIC

CHECK_PERIOD = 0.1
MIN_PERIOD = 0.5
CIRCLE_POINTS = 72
LANDER_HEIGHT = 1.2
PICK_GROUND_ALPHA = 0.01  # drawn all but invisibly: rviz picks by depth, not by colour
REGION_LABEL_HEIGHT = 0.8  # letter height of a region's label
SCORE_HEIGHT = 8.0  # the score text floats this high over the lander (above the TF labels)
SCORE_TEXT = 1.4  # its letter height: readable from the whole site, not a wall over the work
IDENTIFIED = {
    LEVEL_SCIENCE: "identified by the science rover",
    LEVEL_COLLABORATIVE: "identified by both",
}
_BOX_COLORS = {
    "wifi": (0.25, 0.55, 0.95, 1.0),
    "sample": (0.90, 0.90, 0.90, 1.0),
    "lofar": (0.70, 0.40, 0.80, 1.0),
    "power": (0.95, 0.60, 0.15, 1.0),
}


def world_signature(sim: Simulation) -> Hashable:
    """What the markers show, coarsely: the array is republished when this changes."""
    return (
        tuple((r.discovered, r.identified) for r in sim.regions.values()),
        (round(sim.score, 3), sim.delivered),
        tuple(
            (round(b.x, 1), round(b.y, 1), round(b.z, 1), b.deployed) for b in sim.boxes.values()
        ),
        tuple(bool(s.carried_by) or s.delivered for s in sim.stones.values()),
    )


def world_markers(sim: Simulation) -> MarkerArray:
    """Every marker of the site, after a DELETEALL."""
    clear = Marker(action=Marker.DELETEALL)
    clear.header.frame_id = MAP_FRAME
    return MarkerArray(
        markers=[clear, *_static_markers(sim), *_box_markers(sim), *_science_markers(sim)]
    )


def _marker(ns: str, ident: int, kind: int, x: float, y: float, z: float) -> Marker:
    marker = Marker(ns=ns, id=ident, type=kind, action=Marker.ADD)
    marker.header.frame_id = MAP_FRAME
    marker.header.stamp = rospy.Time(0)
    marker.pose.position = Point(x, y, z)
    marker.pose.orientation = yaw_quaternion(0.0)
    marker.color = ColorRGBA(*PALETTE[ns])
    return marker


def _sized(marker: Marker, sx: float, sy: float, sz: float, yaw: float = 0.0) -> Marker:
    marker.scale.x, marker.scale.y, marker.scale.z = sx, sy, sz
    marker.pose.orientation = yaw_quaternion(yaw)
    return marker


def _static_markers(sim: Simulation) -> list[Marker]:
    scenario = sim.scenario
    x_min, x_max, y_min, y_max = scenario.bounds
    ground = _marker("ground", 0, Marker.CUBE, (x_min + x_max) / 2, (y_min + y_max) / 2, -0.05)
    out = [_sized(ground, x_max - x_min, y_max - y_min, 0.1), _pick_ground(sim)]
    for i, o in enumerate(scenario.obstacles):
        if o.shape == "cylinder":
            m = _marker("obstacles", i, Marker.CYLINDER, o.x, o.y, o.height / 2)
            out.append(_sized(m, 2 * o.radius, 2 * o.radius, o.height))
        else:
            m = _marker("obstacles", i, Marker.CUBE, o.x, o.y, o.height / 2)
            out.append(_sized(m, o.size_x, o.size_y, o.height, o.yaw))
    for i, s in enumerate(scenario.slopes):
        out.append(
            _sized(_marker("slopes", i, Marker.CUBE, s.x, s.y, 0.01), s.size_x, s.size_y, 0.02)
        )
    side = 2 * scenario.lander_radius
    lander = _marker("lander", 0, Marker.CUBE, 0.0, 0.0, LANDER_HEIGHT / 2)
    out.append(_sized(lander, side, side, LANDER_HEIGHT))
    return out


def _pick_ground(sim: Simulation) -> Marker:
    """A slab the size of the site just under the grid, for rviz's picking (Publish Point)."""
    x_min, x_max, y_min, y_max = sim.scenario.bounds
    slab = _marker("ground", 0, Marker.CUBE, (x_min + x_max) / 2, (y_min + y_max) / 2, -0.01)
    slab.ns = "pick_ground"  # its own namespace: shown even where the ground is hidden
    slab.color = ColorRGBA(*PALETTE["ground"][:3], PICK_GROUND_ALPHA)
    return _sized(slab, x_max - x_min, y_max - y_min, 0.02)


def region_label_x(x: float, radius: float, text: str) -> float:
    """Where a region's label is centred: east of its disc, clear of what stands inside."""
    longest = max(len(line) for line in text.splitlines())
    return x + radius + 0.5 + longest * REGION_LABEL_HEIGHT * CHAR_WIDTH / 2


def _box_markers(sim: Simulation) -> list[Marker]:
    out = []
    for i, box in enumerate(sim.boxes.values()):
        m = _sized(_marker("boxes", i, Marker.CUBE, box.x, box.y, box.z), *(BOX_SIZE,) * 3)
        m.color = ColorRGBA(*_BOX_COLORS.get(box.spec.kind, PALETTE["boxes"]))
        out.append(m)
    sources = [(0.0, 0.0, sim.scenario.lander_wifi_radius)]
    sources += [
        (b.x, b.y, b.spec.wifi_radius)
        for b in sim.boxes.values()
        if b.deployed and b.spec.kind == "wifi"
    ]
    for i, (x, y, radius) in enumerate(sources):
        out.append(_circle("wifi", i, x, y, radius))
    return out


def _circle(ns: str, ident: int, x: float, y: float, radius: float) -> Marker:
    marker = _marker(ns, ident, Marker.LINE_STRIP, 0.0, 0.0, 0.05)
    marker.scale.x = 0.1  # line width
    marker.points = [
        Point(
            x + radius * math.cos(2 * math.pi * k / CIRCLE_POINTS),
            y + radius * math.sin(2 * math.pi * k / CIRCLE_POINTS),
            0.0,
        )
        for k in range(CIRCLE_POINTS + 1)
    ]
    return marker


def _science_markers(sim: Simulation) -> list[Marker]:
    out = []
    for i, region in enumerate(sim.regions.values()):
        if not region.discovered:
            continue
        spec = region.spec
        disc = _marker("regions", i, Marker.CYLINDER, spec.x, spec.y, 0.02)
        out.append(_sized(disc, 2 * spec.radius, 2 * spec.radius, 0.04))
        how = IDENTIFIED.get(region.identified, "not identified")
        left = sim.stones_left(spec.name)
        text = f"{spec.name} (max {spec.max_score:g})\n{how}, {left} left"
        x = region_label_x(spec.x, spec.radius, text)
        label = _marker("region_labels", i, Marker.TEXT_VIEW_FACING, x, spec.y, 0.5)
        label.scale.z = REGION_LABEL_HEIGHT
        label.text = text
        out.append(label)
    score = _marker("score", 0, Marker.TEXT_VIEW_FACING, 0.0, 0.0, SCORE_HEIGHT)
    score.scale.z = SCORE_TEXT
    score.text = f"science score {sim.score:.2f}\n{counted(sim.delivered, 'stone')} delivered"
    out.append(score)
    discovered = {name for name, r in sim.regions.items() if r.discovered}
    for i, stone in enumerate(sim.stones.values()):
        if stone.region in discovered and not stone.carried_by and not stone.delivered:
            m = _marker("stones", i, Marker.SPHERE, stone.x, stone.y, STONE_RADIUS)
            out.append(_sized(m, *(2 * STONE_RADIUS,) * 3))
    return out


class WorldPublisher:
    """Republishes the world markers when what they show changes."""

    def __init__(self, sim: Simulation) -> None:
        self.sim = sim
        self._shown: Hashable = None
        self._check = Throttle(CHECK_PERIOD)
        self._send = Throttle(MIN_PERIOD)
        self._publisher = rospy.Publisher(WORLD_TOPIC, MarkerArray, queue_size=2, latch=True)

    def after_step(self, now: float) -> None:
        """Publish if the world looks different and the last array is old enough."""
        if not self._check.due(now):
            return
        signature = world_signature(self.sim)
        if signature != self._shown and self._send.due(now):
            self._shown = signature
            self._publisher.publish(world_markers(self.sim))
