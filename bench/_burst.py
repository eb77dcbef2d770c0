"""The ``/rosmc/mission`` snapshot after a burst of changes (for bench_server.py).

``tests/integration/test_server_services.py`` checks the outcome (a new subscriber gets the
current mission; a change is not resent to the subscribers already there); this module
measures how long a subscriber that joins right after a burst waits for it.
"""

from __future__ import annotations

import threading
import time
from typing import Any

from _server_harness import ServerClient

CONNECT_S = 2.0  # the subscriber connects and its first snapshot arrives
GIVE_UP_S = 60.0  # the snapshot at the burst's revision never came: the figure says so


class _Snapshots:
    """A subscriber to ``/rosmc/mission`` that keeps (receive time, revision) of each."""

    def __init__(self, client: ServerClient) -> None:
        import rosmc.msg as wire

        from rosmc_server import interface

        self.arrived: list[tuple[float, int]] = []
        self.landed = threading.Condition()
        self.subscriber = client.rospy.Subscriber(
            interface.MISSION_TOPIC, wire.Mission, self._on_snapshot
        )

    def _on_snapshot(self, msg: Any) -> None:
        with self.landed:
            self.arrived.append((time.perf_counter(), msg.revision))
            self.landed.notify_all()

    def first_at(self, revision: int) -> float | None:
        """When the snapshot of ``revision`` arrived (waits for it; None if it never did)."""
        with self.landed:
            self.landed.wait_for(lambda: any(r == revision for _, r in self.arrived), GIVE_UP_S)
            return next((t for t, r in self.arrived if r == revision), None)


def snapshot_after_burst(client: ServerClient, agent: str, adds: int = 200) -> dict[str, Any]:
    """Send ``adds`` add_skill calls back to back; then time a new subscriber's snapshot.

    Returns ``ms_join_to_snapshot`` (a subscriber that joins after the burst → its first
    snapshot, which is at the burst's revision; None if none came within a minute) and
    ``snapshots``
    (how many the burst sent a subscriber that was there before it: none since changes
    are no longer broadcast).
    """
    early = _Snapshots(client)
    try:
        time.sleep(CONNECT_S)
        before = len(early.arrived)
        for _ in range(adds):
            client.call("add_skill", base_revision=client.rev, agent=agent, skill="wait", index=-1)
        last = client.rev
        time.sleep(CONNECT_S)  # what the burst sends it comes meanwhile
        during = len(early.arrived) - before
    finally:
        early.subscriber.unregister()  # the late joiner must connect afresh
    joined = time.perf_counter()
    late = _Snapshots(client)
    try:
        caught_up = late.first_at(last)
    finally:
        late.subscriber.unregister()
    return {
        "adds": adds,
        "ms_join_to_snapshot": None if caught_up is None else round((caught_up - joined) * 1e3, 1),
        "snapshots": during,
    }
