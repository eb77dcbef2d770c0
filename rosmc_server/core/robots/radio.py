"""The radio side channel, free of ROS: datagram framing and who is in contact.

Topics between the ground and robots travel over TCP, whose retransmission backoff grows
during an outage (to minutes by default): after a radio returns, a connection may stay
silent for as long again. What must cross the radio at once therefore goes as UDP
datagrams, repeated by its senders: barrier signals between robots, and beacons by which
each end learns within a beacon period that the other is back (the ROS adapter then
reconnects the link's topics instead of waiting on the kernel's backoff).

Every datagram is signed with the deployment's key and refused if it is not, or if it is
an old one played again (:mod:`.radio_auth` has the layout and the rules): a beacon carries
only its sender's name, a barrier signal a serialized ``rosmc/BarrierSignal`` as well.

An idle radio should carry little: a robot that hears the ground beacons it only every
:data:`IDLE_BEACON_PERIOD` s (:class:`BeaconPlan`). While it does not hear the ground, and
just after it hears it again, it sends *return* beacons every :data:`BEACON_PERIOD` s; the
ground takes the first of them as the robot's return (:meth:`ContactWatch.heard`), so an
outage is still repaired within a beacon period of the radio's return. Each end also reads
the directory of endpoints less often while it does not change
(:func:`next_directory_period`).
"""

from __future__ import annotations

import enum
from dataclasses import dataclass, field

from ..errors import InvalidRequest

MAX_DATAGRAM = 1400  # bytes: one datagram fits an Ethernet frame, never fragmented
BEACON_PERIOD = 0.5  # seconds between beacons to each peer (a robot's: while seeking)
IDLE_BEACON_PERIOD = 4.0  # seconds between a robot's beacons while it hears the ground
SILENCE = 1.5  # seconds unheard after which a peer counts as out of contact
ROBOT_SILENCE = 2.5 * IDLE_BEACON_PERIOD  # the same, for the ground hearing a robot
DIRECTORY_PERIOD = 2.0  # seconds between reads of the endpoint directory after a change
DIRECTORY_MAX_PERIOD = 30.0  # ... doubling up to this while it stays the same


class DatagramKind(enum.IntEnum):
    """What a datagram carries."""

    BEACON = 1
    BARRIER_SIGNAL = 2
    RETURN_BEACON = 3  # a beacon of a sender that does not hear the receiver, or just did again


def parse_endpoint(text: str) -> tuple[str, int]:
    """``host:port`` as a pair (InvalidRequest if malformed)."""
    host, sep, port = text.rpartition(":")
    if not sep or not host or not port.isdigit() or not 0 < int(port) < 65536:
        raise InvalidRequest(f"a radio endpoint is 'host:port', got {text!r}")
    return host.strip("[]"), int(port)


def next_directory_period(period: float, changed: bool) -> float:
    """Seconds until the next read of the directory, after one that waited ``period``.

    Back to :data:`DIRECTORY_PERIOD` when the read found a change (a peer started or
    restarted), else twice as long, up to :data:`DIRECTORY_MAX_PERIOD`: every read is an
    XML-RPC exchange with the master over the radio.
    """
    return DIRECTORY_PERIOD if changed else min(DIRECTORY_MAX_PERIOD, 2.0 * period)


@dataclass
class ContactWatch:
    """When each peer was last heard, and whether it has just come back after a silence.

    Args:
        silence: Seconds unheard after which a peer is out of contact.
    """

    silence: float = SILENCE
    _last: dict[str, float] = field(default_factory=dict)
    _returning: dict[str, float] = field(default_factory=dict)  # its last return beacon

    def heard(self, peer: str, now: float, returning: bool = False) -> bool:
        """Note ``peer`` heard at ``now``; True if contact is back.

        Contact is back when the peer had been silent, or when ``returning`` (a return
        beacon: the peer did not hear this end) is the first of a series. Never on the
        first contact: no connection can have stalled yet.
        """
        last = self._last.get(peer)
        self._last[peer] = now
        series = self._returning.get(peer)
        if returning:
            self._returning[peer] = now
        if last is None:
            return False
        if now - last > self.silence:
            return True
        return returning and (series is None or now - series > SILENCE)

    def in_contact(self, peer: str, now: float) -> bool:
        """Whether ``peer`` was heard within the silence."""
        last = self._last.get(peer)
        return last is not None and now - last <= self.silence


@dataclass
class BeaconPlan:
    """When a robot beacons the ground, and which kind of beacon it sends.

    Plain beacons every ``idle_period`` s while it hears the ground; return beacons every
    ``period`` s while it does not, and for ``period`` s after it hears it again (two or
    three of them, in case one is lost), starting at once.
    """

    period: float = BEACON_PERIOD
    idle_period: float = IDLE_BEACON_PERIOD
    silence: float = SILENCE
    _heard: float | None = None
    _back: float = float("-inf")
    _next: float = 0.0
    _plain: bool = False  # the last beacon sent was a plain one

    def heard(self, now: float) -> None:
        """The ground was heard at ``now``."""
        if self._heard is None or now - self._heard > self.silence:
            self._back, self._next = now, now
        self._heard = now

    def due(self, now: float) -> DatagramKind | None:
        """The beacon to send at ``now``, or None if none is due.

        When the ground falls silent the first return beacon goes at once, not when the
        idle period is up.
        """
        unheard = self._heard is None or now - self._heard > self.silence
        seeking = unheard or now - self._back <= self.period
        if now < self._next and not (seeking and self._plain):
            return None
        self._plain = not seeking
        self._next = now + (self.period if seeking else self.idle_period)
        return DatagramKind.RETURN_BEACON if seeking else DatagramKind.BEACON
