"""The radio side channel, free of ROS: datagram framing and who is in contact.

Topics between the ground and robots travel over TCP, whose retransmission backoff grows
during an outage (to minutes by default): after a radio returns, a connection may stay
silent for as long again. What must cross the radio at once therefore goes as UDP
datagrams, repeated by its senders: barrier signals between robots, and beacons by which
each end learns within a beacon period that the other is back (the ROS adapter then
reconnects the link's topics instead of waiting on the kernel's backoff).

A datagram is ``MAGIC``, one kind byte, and the payload: a beacon carries the sender's
name (UTF-8), a barrier signal a serialized ``rosmc/BarrierSignal``.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass, field

from .errors import InvalidRequest

MAGIC = b"RMC\x01"
MAX_DATAGRAM = 1400  # bytes: one datagram fits an Ethernet frame, never fragmented
BEACON_PERIOD = 0.5  # seconds between beacons to each peer
SILENCE = 1.5  # seconds unheard after which a peer counts as out of contact


class DatagramKind(enum.IntEnum):
    """What a datagram carries."""

    BEACON = 1
    BARRIER_SIGNAL = 2


def encode_datagram(kind: DatagramKind, payload: bytes) -> bytes:
    """One datagram (InvalidRequest if the payload does not fit)."""
    data = MAGIC + bytes((int(kind),)) + payload
    if len(data) > MAX_DATAGRAM:
        raise InvalidRequest(
            f"a {kind.name.lower()} datagram holds at most {MAX_DATAGRAM} bytes, "
            f"this one {len(data)}"
        )
    return data


def decode_datagram(data: bytes) -> tuple[DatagramKind, bytes]:
    """The kind and payload of a datagram (InvalidRequest if it is not one of ours)."""
    if len(data) <= len(MAGIC) or not data.startswith(MAGIC):
        raise InvalidRequest("not a ROSMC radio datagram")
    try:
        kind = DatagramKind(data[len(MAGIC)])
    except ValueError:
        raise InvalidRequest(f"unknown radio datagram kind {data[len(MAGIC)]}") from None
    return kind, data[len(MAGIC) + 1 :]


def parse_endpoint(text: str) -> tuple[str, int]:
    """``host:port`` as a pair (InvalidRequest if malformed)."""
    host, sep, port = text.rpartition(":")
    if not sep or not host or not port.isdigit() or not 0 < int(port) < 65536:
        raise InvalidRequest(f"a radio endpoint is 'host:port', got {text!r}")
    return host.strip("[]"), int(port)


@dataclass
class ContactWatch:
    """When each peer was last heard, and whether it has just come back after a silence.

    Args:
        silence: Seconds unheard after which a peer is out of contact.
    """

    silence: float = SILENCE
    _last: dict[str, float] = field(default_factory=dict)

    def heard(self, peer: str, now: float) -> bool:
        """Note ``peer`` heard at ``now``; True if it had been silent (contact is back)."""
        last = self._last.get(peer)
        self._last[peer] = now
        return last is not None and now - last > self.silence

    def in_contact(self, peer: str, now: float) -> bool:
        """Whether ``peer`` was heard within the silence."""
        last = self._last.get(peer)
        return last is not None and now - last <= self.silence
