"""Bytes each subscriber of the mission server receives per isolated change; prints JSON.

Starts its own ``rosmaster`` on a free loopback port and, per mission size (agents x
skills per agent), a real ``mission_server`` with the mission loaded as one document. One
subscriber (``rospy.AnyMsg``: the bytes as they come, nothing decoded) listens to every
topic the server publishes. Then, ``--changes`` times: ``--window`` s with nothing
happening, one label edit, ``--window`` s again. Per topic, the bytes after the change
less the bytes of the quiet window before it (topics published at a steady rate, such as
``/rosmc/agent_states``, cost the same in both) are what the change cost that
subscriber: the median over the changes, each message counted with its 4-byte length
prefix. ``/rosmc/mission`` is the latched snapshot: a late joiner's first message, which
``late_joiner_snapshot_bytes`` gives too. Each size runs twice: ``now``, and
``broadcast`` with the server's ``~broadcast_snapshots`` (every coalesced snapshot sent
to every subscriber, as before). Run from the repository root::

    source env.sh
    python bench/bench_change_bytes.py [--sizes 2x500,20x500,50x1000] [--changes 3]
"""

from __future__ import annotations

import argparse
import statistics
import sys
import threading
import time
from collections import Counter
from collections.abc import Callable
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parent))

from _missions import library_yaml, mission_yaml
from _server_harness import Server, bench_node, figures_printed, serialized_size
from bench_server import Bench

SERVER_NODE = "/rosmc/mission_server"
CONNECT_S = 3.0  # the subscriptions connect and the latched messages arrive


class TopicBytes:
    """Bytes received per topic on every topic ``SERVER_NODE`` publishes."""

    def __init__(self, rospy: Any) -> None:
        import rosgraph

        publishers, _, _ = rosgraph.Master("/bench_change_bytes").getSystemState()
        self.topics = sorted(t for t, nodes in publishers if SERVER_NODE in nodes)
        self._lock = threading.Lock()
        self._bytes: Counter[str] = Counter()
        self._first: dict[str, int] = {}
        self._subscribers = [
            rospy.Subscriber(topic, rospy.AnyMsg, self._counter(topic), queue_size=1000)
            for topic in self.topics
        ]

    def _counter(self, topic: str) -> Any:
        def count(msg: Any) -> None:
            # A topic this process also takes typed (the client's events) comes decoded.
            size = (len(msg._buff) if hasattr(msg, "_buff") else serialized_size(msg)) + 4
            with self._lock:
                self._bytes[topic] += size
                self._first.setdefault(topic, size)

        return count

    def first(self, topic: str) -> int:
        """The size of the first message of ``topic`` (0 if none came)."""
        with self._lock:
            return self._first.get(topic, 0)

    def window(self, seconds: float, action: Callable[[], None] | None = None) -> Counter[str]:
        """Bytes per topic received over the next ``seconds``, ``action`` done first."""
        with self._lock:
            before = Counter(self._bytes)
        started = time.monotonic()
        if action is not None:
            action()  # its event may arrive before the service answers
        time.sleep(max(0.0, started + seconds - time.monotonic()))
        with self._lock:
            after = Counter(self._bytes)
        return Counter({t: after[t] - before[t] for t in self.topics})

    def close(self) -> None:
        """Unsubscribe."""
        for subscriber in self._subscribers:
            subscriber.unregister()


def folded(figures: dict[str, int]) -> dict[str, int]:
    """``/rosmc/link/<agent>/<topic>`` as ``/rosmc/link/*/<topic>`` (the largest figure)."""
    out: dict[str, int] = {}
    for topic, value in figures.items():
        parts = topic.split("/")
        if topic.startswith("/rosmc/link/") and len(parts) == 5:
            topic = f"/rosmc/link/*/{parts[4]}"
        out[topic] = max(out.get(topic, 0), value)
    return out


def bench_size(
    env: dict[str, str], work: Path, agents: int, skills: int, args: Any, broadcast: bool
) -> dict[str, Any]:
    """The bytes per isolated change of one mission size, against a server of its own."""
    work.mkdir(parents=True, exist_ok=True)
    library = work / "library.yaml"
    library.write_text(library_yaml(agents))
    params = [f"_broadcast_snapshots:={str(broadcast).lower()}"]
    server = Server(env, work, library, None, params)
    try:
        bench = Bench(agents, skills, 0)
        bench.call("load_mission", base_revision=bench.rev, document=mission_yaml(agents, skills))
        time.sleep(1.0)  # the loaded mission's snapshot is built
        topics = TopicBytes(bench.rospy)
        time.sleep(CONNECT_S)
        per_change: dict[str, list[int]] = {t: [] for t in topics.topics}
        for _ in range(args.changes):
            quiet = topics.window(args.window)
            changed = topics.window(args.window, bench.edit_label)
            for topic in topics.topics:
                per_change[topic].append(max(0, changed[topic] - quiet[topic]))
        result = {
            "agents": agents,
            "skills_per_agent": skills,
            "total_skills": agents * skills,
            "late_joiner_snapshot_bytes": topics.first("/rosmc/mission"),
            # Topics alike (every robot's command and report_ack) folded into one line each.
            "bytes_per_change": folded(
                {t: int(statistics.median(v)) for t, v in per_change.items()}
            ),
        }
        topics.close()
        bench.close()
    finally:
        server.stop()
    return result


def main(argv: list[str] | None = None) -> int:
    """Run the benchmark and print its JSON."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", default="2x500,20x500,50x1000", help="AGENTSxSKILLS,...")
    parser.add_argument("--changes", type=int, default=3, help="isolated changes per size")
    # The report_ack topics carry a heartbeat every 2 s: both windows hold as many.
    parser.add_argument("--window", type=float, default=4.0, help="seconds (a multiple of 2)")
    args = parser.parse_args(argv)
    sizes = [tuple(int(x) for x in size.split("x")) for size in args.sizes.split(",")]
    output: dict[str, Any] = {"sizes": []}
    with figures_printed(output), bench_node("bench_bytes_", "bench_change_bytes") as (base, env):
        for a, s in sizes:
            modes = (("now", False), ("broadcast", True))
            output["sizes"].append(
                {"skills": a * s}
                | {
                    mode: bench_size(env, base / f"{a}x{s}{mode}", a, s, args, broadcast)
                    for mode, broadcast in modes
                }
            )
    return 0


if __name__ == "__main__":
    sys.exit(main())
