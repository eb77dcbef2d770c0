"""The one place that speaks ``interactive_markers``' camelCase API.

:class:`MarkerServer` stages inserts, pose changes and erases and publishes them with one
``applyChanges()`` (one ``InteractiveMarkerUpdate`` per batch). Feedback for markers the
server does not hold is dropped by the stock server without a word; here it is logged as
a warning. And the stock server refuses every feedback for a marker's first second (it
takes the marker's creation for a feedback from a client called ""); here the first
client to send feedback is simply taken as the marker's current client.
"""

from __future__ import annotations

import logging
from collections.abc import Callable

from geometry_msgs.msg import Pose
from interactive_markers.interactive_marker_server import InteractiveMarkerServer
from visualization_msgs.msg import InteractiveMarker, InteractiveMarkerFeedback

_log = logging.getLogger(__name__)

FeedbackCallback = Callable[[InteractiveMarkerFeedback], None]


class _Server(InteractiveMarkerServer):  # type: ignore[misc]
    """The stock server, warning about feedback for markers it does not hold."""

    def processFeedback(self, feedback: InteractiveMarkerFeedback) -> None:
        if feedback.marker_name not in self.marker_contexts:
            _log.warning(
                "ignored feedback for unknown marker '%s' (from %s)",
                feedback.marker_name,
                feedback.client_id or "?",
            )
            return
        context = self.marker_contexts[feedback.marker_name]
        if not context.last_client_id:
            context.last_client_id = feedback.client_id
        super().processFeedback(feedback)


class MarkerServer:
    """An ``interactive_markers`` server under topic namespace ``topic_ns``.

    Publishes ``<topic_ns>/update`` and ``<topic_ns>/update_full`` (latched) and
    subscribes ``<topic_ns>/feedback`` (visualization_msgs). Every marker's feedback goes
    to ``on_feedback``.
    """

    def __init__(self, topic_ns: str, on_feedback: FeedbackCallback) -> None:
        self._server = _Server(topic_ns, q_size=1000)
        self._on_feedback = on_feedback

    def insert(self, marker: InteractiveMarker) -> None:
        """Stage a new or replaced marker (published by :meth:`apply`)."""
        self._server.insert(marker, self._on_feedback)

    def set_pose(self, name: str, pose: Pose, frame: str) -> None:
        """Stage a new pose of an existing marker."""
        header = self._server.get(name).header
        header.frame_id = frame
        self._server.setPose(name, pose, header)

    def erase(self, name: str) -> None:
        """Stage the removal of a marker."""
        self._server.erase(name)

    def apply(self) -> None:
        """Publish everything staged as one update."""
        self._server.applyChanges()

    def clear(self) -> None:
        """Remove every marker (published at once)."""
        self._server.clear()
        self._server.applyChanges()
