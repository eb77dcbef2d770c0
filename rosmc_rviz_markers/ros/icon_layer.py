"""The status icons topic: every robot's block once to a new subscriber, then only changes.

Publishes ``<ns>/rosmc/markers/icons`` (visualization_msgs/MarkerArray). A latched topic
would have to carry every block in every message (a latch keeps only the last one), so
each agent-state message (2 Hz, 20 robots) would resend all of them. Instead a subscriber
that connects is sent the whole set on its own connection (as a latch would), and after
that each message carries only the icon markers whose text, colour or place changed, and
a DELETE for each that is gone.
"""

from __future__ import annotations

import threading
from collections.abc import Callable, Sequence

import rospy
from visualization_msgs.msg import Marker, MarkerArray

Key = tuple[str, int]


class _Joiners(rospy.SubscribeListener):  # type: ignore[misc]
    """Sends the whole current set to each subscriber as it connects."""

    def __init__(self, whole: Callable[[], list[Marker]]) -> None:
        super().__init__()
        self._whole = whole

    def peer_subscribe(
        self, topic_name: str, topic_publish: object, peer_publish: Callable[[MarkerArray], None]
    ) -> None:
        del topic_name, topic_publish
        peer_publish(MarkerArray(markers=self._whole()))


class IconLayer:
    """Publishes status icon markers as changes (see the module docstring)."""

    def __init__(self, topic: str) -> None:
        self._lock = threading.Lock()  # the shown set; a joiner's copy is taken under it
        self._shown: dict[Key, Marker] = {}
        self._publisher = rospy.Publisher(
            topic, MarkerArray, queue_size=10, subscriber_listener=_Joiners(self.whole)
        )

    def whole(self) -> list[Marker]:
        """Every icon marker shown now."""
        with self._lock:
            return list(self._shown.values())

    def show(self, markers: Sequence[Marker]) -> int:
        """Show exactly ``markers``; publishes what differs. Returns how many it sent."""
        with self._lock:
            new = {(m.ns, m.id): m for m in markers}
            changed = [m for key, m in new.items() if self._shown.get(key) != m]
            for ns, marker_id in self._shown.keys() - new.keys():
                changed.append(Marker(ns=ns, id=marker_id, action=Marker.DELETE))
            self._shown = new
            if changed:
                # under the lock, so a subscriber joining now gets the set before this change
                self._publisher.publish(MarkerArray(markers=changed))
            return len(changed)
