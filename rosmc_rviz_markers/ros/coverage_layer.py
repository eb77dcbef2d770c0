"""rviz's radio-coverage layer: ``/rosmc/coverage`` (visualization_msgs/MarkerArray).

Builds a :class:`~rosmc_server.core.robots.radio_map.RadioMap` from the robots' telemetry in
``/rosmc/agent_states`` (rosmc/AgentStates; journaled, so a replay grows the same map) and
the radio model ``/rosmc/sim/coverage`` (rosmc/CoverageGrid, with the simulator), and
draws it (:mod:`rosmc_rviz_markers.core.coverage`): namespace ``coverage_model`` (the
model, one CUBE_LIST), ``coverage_measured`` (the readings, one CUBE_LIST),
``last_link`` (a pole per robot where it last had a link) and ``last_link_label`` (its
reading and age). Ages count from the newest agent-states stamp, so a replay shows them
as they were. Published at most every :data:`PERIOD` wall seconds; every name behind
the node's ``ns``.
"""

from __future__ import annotations

import threading
import time

import rosmc.msg as wire
import rospy
from geometry_msgs.msg import Point
from std_msgs.msg import ColorRGBA
from visualization_msgs.msg import Marker, MarkerArray

from rosmc_server.conversions.coverage import prediction_from_msg, reading_from_telemetry
from rosmc_server.core.robots.radio_map import RadioMap
from rosmc_server.core.views.geometry import Color
from rosmc_server.interface import (
    AGENT_STATES_TOPIC,
    COVERAGE_MARKERS_TOPIC,
    COVERAGE_MODEL_TOPIC,
    MAP_FRAME,
    prefixed,
)

from ..core.coverage import Cell, LastLink, last_links, measured_cells, model_cells

PERIOD = 1.0
POLE_HEIGHT = 1.6
LABEL_SOUTH = 1.6  # the last-link label, this far south of its pole (m)


class CoverageLayer:
    """Keeps the radio map and publishes it for rviz."""

    def __init__(self, ns: str = "") -> None:
        self._lock = threading.Lock()
        self._radio = RadioMap()
        self._now = 0.0
        self._in_contact: frozenset[str] = frozenset()  # robots whose link is up
        self._next = 0.0
        self._publisher = rospy.Publisher(
            prefixed(COVERAGE_MARKERS_TOPIC, ns), MarkerArray, queue_size=2, latch=True
        )
        self._subscribers = [
            rospy.Subscriber(
                prefixed(AGENT_STATES_TOPIC, ns), wire.AgentStates, self._on_states, queue_size=5
            ),
            rospy.Subscriber(
                prefixed(COVERAGE_MODEL_TOPIC, ns), wire.CoverageGrid, self._on_model, queue_size=1
            ),
        ]

    def _on_states(self, msg: wire.AgentStates) -> None:
        with self._lock:
            self._now = max(self._now, msg.stamp.to_sec())
            self._in_contact = frozenset(
                state.agent for state in msg.agents if state.link.state == wire.LinkState.UP
            )
            for state in msg.agents:
                telemetry = state.telemetry
                if telemetry.frame_id or not telemetry.stamp.is_zero():
                    self._radio.add(reading_from_telemetry(telemetry))
        self._publish(force=False)

    def _on_model(self, msg: wire.CoverageGrid) -> None:
        with self._lock:
            self._radio.prediction = prediction_from_msg(msg)
        self._publish(force=True)

    def _publish(self, force: bool) -> None:
        if not force and time.monotonic() < self._next:
            return
        self._next = time.monotonic() + PERIOD
        with self._lock:
            model = model_cells(self._radio)
            measured = measured_cells(self._radio, self._now)
            marks = last_links(self._radio, self._now, self._in_contact)
        out = MarkerArray()
        # Under the site's pick ground (its top at z = 0) and every interactive marker: rviz
        # picks the nearest surface, so shading above them would take the operator's clicks
        # (Publish Point, drags) for itself. The readings lie above the model.
        if model:
            out.markers.append(_cubes("coverage_model", model, -0.045, 0.01))
        if measured:
            out.markers.append(_cubes("coverage_measured", measured, -0.03, 0.01))
        for index, mark in enumerate(marks):
            out.markers += _last_link(index, mark)
        self._publisher.publish(out)


def _rgba(color: Color) -> ColorRGBA:
    return ColorRGBA(color.r, color.g, color.b, color.a)


def _marker(ns: str, marker_id: int, kind: int) -> Marker:
    marker = Marker(ns=ns, id=marker_id, type=kind, action=Marker.ADD)
    marker.header.frame_id = MAP_FRAME
    marker.pose.orientation.w = 1.0
    return marker


def _cubes(ns: str, cells: list[Cell], z: float, height: float) -> Marker:
    marker = _marker(ns, 0, Marker.CUBE_LIST)
    marker.scale.x = marker.scale.y = cells[0].size
    marker.scale.z = height
    marker.color = ColorRGBA(1.0, 1.0, 1.0, 1.0)  # the per-point colours count
    marker.points = [Point(c.x, c.y, z) for c in cells]
    marker.colors = [_rgba(c.color) for c in cells]
    return marker


def _last_link(index: int, mark: LastLink) -> list[Marker]:
    alpha = 0.5 if mark.old else 1.0
    pole = _marker("last_link", index, Marker.CYLINDER)
    pole.pose.position = Point(mark.x, mark.y, POLE_HEIGHT / 2)
    pole.scale.x = pole.scale.y = 0.15
    pole.scale.z = POLE_HEIGHT
    pole.color = ColorRGBA(0.1, 0.4, 1.0, alpha)
    label = _marker("last_link_label", index, Marker.TEXT_VIEW_FACING)
    if not mark.label:  # rviz flags an empty text as an error: take the label away instead
        label.action = Marker.DELETE
        return [pole, label]
    # south of the pole's foot (below it on screen), not over its top: a robot standing
    # at its last-link place (the drone on the lander) keeps its pin clear to click
    label.pose.position = Point(mark.x, mark.y - LABEL_SOUTH, 0.3)
    label.scale.z = 0.5
    label.color = ColorRGBA(1.0, 1.0, 1.0, alpha)
    label.text = mark.label
    return [pole, label]
