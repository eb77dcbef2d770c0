"""What a host sends on one interface, by kind of traffic (for bench_idle_link.py).

Run inside a network namespace as root: ``python bench/_sniff.py IFACE SECONDS
[MASTER_PORT]``. It reads every frame the interface sends for ``SECONDS`` (a raw
``AF_PACKET`` socket; frames counted whole, Ethernet header included, as ``tc`` counts
them) and prints one JSON object of bytes and frames per kind:

* ``udp``: the radio side channel (beacons, barrier signals);
* ``master``: TCP to or from the ROS master (XML-RPC: the radio directory, parameters);
* ``tcp_data``: other TCP segments that carry data (ROS topics: snapshots, reports, acks);
* ``tcp_ack``: other TCP segments without data (the kernel acknowledging what it received);
* ``other``: the rest (ARP, ...).
"""

from __future__ import annotations

import json
import socket
import struct
import sys
import time

ETH_P_ALL = 0x0003
PACKET_OUTGOING = 4


def kind_of(frame: bytes, master_port: int) -> str:
    """The kind of one Ethernet frame (see the module docstring)."""
    if len(frame) < 34 or frame[12:14] != b"\x08\x00":
        return "other"
    ip = frame[14:]
    header = (ip[0] & 0x0F) * 4
    protocol = ip[9]
    if protocol == socket.IPPROTO_UDP:
        return "udp"
    if protocol != socket.IPPROTO_TCP:
        return "other"
    total = struct.unpack("!H", ip[2:4])[0]
    tcp = ip[header:]
    source, target = struct.unpack("!HH", tcp[:4])
    if master_port in (source, target):
        return "master"
    data = total - header - (tcp[12] >> 4) * 4
    return "tcp_data" if data > 0 else "tcp_ack"


def sniff(interface: str, seconds: float, master_port: int) -> dict[str, dict[str, float]]:
    """Bytes and frames sent on ``interface`` over ``seconds``, per kind, per second."""
    sock = socket.socket(socket.AF_PACKET, socket.SOCK_RAW, socket.htons(ETH_P_ALL))
    sock.bind((interface, 0))
    sock.settimeout(0.2)
    counts: dict[str, list[int]] = {}
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        try:
            frame, address = sock.recvfrom(65535)
        except TimeoutError:
            continue
        if address[2] != PACKET_OUTGOING:
            continue
        entry = counts.setdefault(kind_of(frame, master_port), [0, 0])
        entry[0] += len(frame)
        entry[1] += 1
    sock.close()
    return {
        kind: {"bytes_per_s": round(b / seconds, 1), "frames_per_s": round(n / seconds, 2)}
        for kind, (b, n) in sorted(counts.items())
    }


if __name__ == "__main__":
    port = int(sys.argv[3]) if len(sys.argv) > 3 else 11311
    print(json.dumps(sniff(sys.argv[1], float(sys.argv[2]), port)))
