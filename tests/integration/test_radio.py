"""The radio side channel between real endpoints on a real master's directory."""

from __future__ import annotations

import socket
import threading
from io import BytesIO
from pathlib import Path

import rosmc.msg as wire
import rospy

from rosmc_server import interface
from rosmc_server.common.ros.radio import Radio
from rosmc_server.core.robots.radio import DatagramKind
from rosmc_server.core.robots.radio_auth import Sealer
from rosmc_server.core.robots.radio_key import RadioKey
from tests.conftest import RosMaster, wait_until


class Heard:
    """What one endpoint heard."""

    def __init__(self) -> None:
        self.beacons: list[str] = []
        self.returns: list[str] = []  # senders of return beacons
        self.signals: list[wire.BarrierSignal] = []
        self.lock = threading.Lock()

    def beacon(self, sender: str, returning: bool) -> None:
        with self.lock:
            self.beacons.append(sender)
            if returning:
                self.returns.append(sender)

    def signal(self, msg: wire.BarrierSignal) -> None:
        with self.lock:
            self.signals.append(msg)


def test_endpoints_find_each_other_through_the_directory(ros_master: RosMaster) -> None:
    # Names of this test's own: the session's master may list endpoints of earlier tests.
    heard = {name: Heard() for name in ("ground", "radio_r1", "radio_r2")}
    key = RadioKey(bytes(32), Path("test.key"))
    radios = {name: Radio(name, h.beacon, h.signal, key=key) for name, h in heard.items()}
    try:
        directory = ros_master.proxy()
        wait_until(
            lambda: (
                set(directory.getParam("/t", interface.RADIO_DIRECTORY)[2] or {}) >= set(radios)
            ),
            30.0,
            "every endpoint registered",
        )
        wait_until(lambda: "radio_r2" in radios["radio_r1"].robots(), 30.0, "r1 to list r2")
        robots = radios["radio_r1"].robots()
        assert "ground" not in robots and "radio_r1" not in robots, robots
        signal = wire.BarrierSignal(agent="radio_r1", barrier_id="B3", skill_id="s", kind=3)
        signal.stamp = rospy.Time(12, 5)

        def exchanged() -> bool:
            radios["radio_r1"].signal(signal, ["radio_r2"])
            radios["radio_r2"].beacon("ground")
            return bool(heard["radio_r2"].signals) and "radio_r2" in heard["ground"].beacons

        wait_until(exchanged, 30.0, "a signal and a beacon to arrive")
        got = heard["radio_r2"].signals[0]
        assert (got.agent, got.barrier_id, got.kind) == ("radio_r1", "B3", 3)
        assert got.stamp == signal.stamp
        assert not heard["ground"].signals  # signals go to robots only
        assert "radio_r2" not in heard["ground"].returns  # a plain beacon

        def returned() -> bool:
            radios["radio_r2"].beacon("ground", DatagramKind.RETURN_BEACON)
            return "radio_r2" in heard["ground"].returns

        wait_until(returned, 30.0, "a return beacon to arrive as one")

        # Stray datagrams never stop the receiver.
        buffer = BytesIO()
        signal.serialize(buffer)
        port = int(radios["radio_r2"].endpoint.rsplit(":", 1)[1])
        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as udp:
            short = Sealer(key, "radio_r1").seal(DatagramKind.BARRIER_SIGNAL, b"\x01\x02")
            for stray in (b"junk", short):
                udp.sendto(stray, ("127.0.0.1", port))
        count = len(heard["radio_r2"].signals)
        wait_until(
            lambda: (
                radios["radio_r1"].signal(signal, ["radio_r2"])
                or len(heard["radio_r2"].signals) > count
            ),
            30.0,
            "r2 to hear on after stray datagrams",
        )
    finally:
        for radio in radios.values():
            radio.close()
