"""The whole-mission figures of the server benchmarks: what costs the whole mission.

:class:`WholeMission` times get_mission (decoded by genpy, read into core objects as the
project's client reads it, and as raw bytes, with each client-side read apart), saving (to a
path on the server and returning the document) and loading the saved mission, each right
after a change; :func:`subscriber_cpu` measures the server's CPU while changes come, without
and with a subscriber to the latched ``/rosmc/mission``. Both take a running
:class:`~_server_harness.Server`, a :class:`~_server_harness.ServerClient` of it, and a
function that makes one small change to the mission.
"""

from __future__ import annotations

import statistics
import time
from collections.abc import Callable
from typing import Any

from _server_harness import Server, ServerClient, percentiles, raw_proxy


class WholeMission:
    """Times the operations that cost the whole mission: get, save and load."""

    def __init__(
        self, client: ServerClient, server: Server, repeats: int, change: Callable[[], None]
    ) -> None:
        self.client = client
        self.change = change
        self.server = server
        self.repeats = repeats
        self.times: dict[str, list[float]] = {}

    def timed(self, figure: str, operation: str, **fields: Any) -> Any:
        """Call ``operation``; its time counts for ``figure``."""
        elapsed, response = self.client.timed(operation, **fields)
        self.times.setdefault(figure, []).append(elapsed)
        return response

    def get_and_save(self) -> tuple[str, int]:
        """get_mission (genpy, core objects and raw) and both saves, each after a change.

        Returns the document saved last and the bytes of the document in the answer to a
        save to a path (none: it is returned only on request).
        """
        import rosmc.srv as srv

        from rosmc_server.conversions.unpacking import UnpackedGetMissionResponse

        raw = raw_proxy("get_mission")
        try:
            for _ in range(self.repeats):
                self.change()
                self.timed("get_mission_after_change", "get_mission")
                self.timed("get_mission_same_revision", "get_mission")
                self.change()
                for figure in ("get_mission_wire_after_change", "get_mission_wire_same_revision"):
                    started = time.perf_counter()
                    data = raw.call(raw.request_class()).raw
                    self.times.setdefault(figure, []).append(time.perf_counter() - started)
                started = time.perf_counter()
                srv.GetMissionResponse().deserialize(data)
                elapsed = time.perf_counter() - started
                self.times.setdefault("get_mission_client_decode", []).append(elapsed)
                started = time.perf_counter()
                UnpackedGetMissionResponse().deserialize(data)
                elapsed = time.perf_counter() - started
                self.times.setdefault("get_mission_client_read", []).append(elapsed)
                self.change()
                self.timed("get_mission_core_after_change", "get_mission_core")
                self.timed("get_mission_core_same_revision", "get_mission_core")
                self.change()
                to_path = self.timed("save_to_path", "save_mission", path="bench.yaml")
                self.change()
                document: str = self.timed("save_returning_document", "save_mission").document
        finally:
            raw.close()
        return document, len(to_path.document)

    def run(self) -> dict[str, Any]:
        """Every whole-mission figure; the loads replace the mission with a saved one."""
        document, path_reply_bytes = self.get_and_save()
        figures: dict[str, Any] = {
            "document_bytes": len(document.encode()),
            "path_reply_bytes": path_reply_bytes,
            "server_peak_rss_after_get_and_save_mib": self.server.peak_rss_mib(),
        }
        for _ in range(self.repeats):
            cpu = self.server.cpu_seconds()
            self.timed(
                "load_saved_document",
                "load_mission",
                base_revision=self.client.rev,
                document=document,
            )
            elapsed = self.server.cpu_seconds() - cpu
            self.times.setdefault("load_saved_document_server_cpu", []).append(elapsed)
        figures["server_peak_rss_after_loads_mib"] = self.server.peak_rss_mib()
        phases = self.server.load_phases()[-self.repeats :]  # none from a server not logging them
        if phases:
            names = ("read_and_check", "serialize", "apply_and_journal")
            for name, values in zip(names, zip(*phases, strict=True), strict=True):
                figures[f"load_server_{name}_ms"] = round(statistics.median(values), 1)
        return {name: percentiles(values) for name, values in self.times.items()} | figures


def subscriber_cpu(
    client: ServerClient, server: Server, seconds: float, change: Callable[[], None]
) -> dict[str, Any]:
    """The server's CPU share over ``seconds`` of 10 changes/s, without and with a subscriber
    to the latched ``/rosmc/mission`` (taking the snapshots as bytes: no decoding here)."""
    from rosmc_server import interface

    received: list[int] = []

    def share() -> float:
        cpu, started = server.cpu_seconds(), time.monotonic()
        for tick in range(round(seconds * 10)):
            change()
            time.sleep(max(0.0, started + (tick + 1) * 0.1 - time.monotonic()))
        return (server.cpu_seconds() - cpu) / (time.monotonic() - started)

    time.sleep(3.0)  # the snapshots of what ran before are built and journaled
    without = share()
    subscriber = client.rospy.Subscriber(
        interface.MISSION_TOPIC, client.rospy.AnyMsg, lambda msg: received.append(len(msg._buff))
    )
    time.sleep(3.0)  # connected, and the latched snapshot delivered
    try:
        with_subscriber = share()
    finally:
        subscriber.unregister()
    return {
        "seconds": seconds,
        "changes_per_s": 10,
        "cpu_share_without_subscriber": round(without, 4),
        "cpu_share_with_subscriber": round(with_subscriber, 4),
        "subscriber_cost_share": round(with_subscriber - without, 4),
        "snapshots_received": len(received),
    }
