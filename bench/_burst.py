"""The latched ``/rosmc/mission`` snapshot after a burst of changes (for bench_server.py).

``tests/integration/test_server_services.py`` checks the outcome (the snapshot is current
once a burst ends, and coalesced during it); this module measures how long that takes.
"""

from __future__ import annotations

import threading
import time
from typing import Any

from _server_harness import ServerClient

CONNECT_S = 2.0  # the subscriber connects and the latched snapshot arrives
GIVE_UP_S = 60.0  # the snapshot at the burst's revision never came: the figure says so


def snapshot_after_burst(client: ServerClient, agent: str, adds: int = 200) -> dict[str, Any]:
    """Send ``adds`` add_skill calls back to back; then time the snapshot that catches up.

    Returns ``ms_after_last_answer`` (the last answer → the snapshot at its revision, or
    None if none came within a minute) and ``snapshots`` (how many the burst caused).
    """
    import rosmc.msg as wire

    from rosmc_server import interface

    arrived: list[tuple[float, int]] = []
    landed = threading.Condition()

    def on_snapshot(msg: Any) -> None:
        with landed:
            arrived.append((time.perf_counter(), msg.revision))
            landed.notify_all()

    subscriber = client.rospy.Subscriber(interface.MISSION_TOPIC, wire.Mission, on_snapshot)
    try:
        time.sleep(CONNECT_S)
        before = len(arrived)
        for _ in range(adds):
            client.call("add_skill", base_revision=client.rev, agent=agent, skill="wait", index=-1)
        answered, last = time.perf_counter(), client.rev
        with landed:
            landed.wait_for(lambda: any(rev == last for _, rev in arrived), GIVE_UP_S)
            caught_up = next((t for t, rev in arrived if rev == last), None)
            during = len(arrived) - before
    finally:
        subscriber.unregister()
    return {
        "adds": adds,
        "ms_after_last_answer": (
            None if caught_up is None else round((caught_up - answered) * 1e3, 1)
        ),
        "snapshots": during,
    }
