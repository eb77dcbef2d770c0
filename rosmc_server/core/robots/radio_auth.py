"""Signed radio datagrams: only holders of the deployment's key can speak on the radio.

Modelled on MAVLink 2 message signing, with an HMAC in place of MAVLink's bare hash.
A datagram is laid out as (big-endian)::

    offset  size  field
    0       4     MAGIC  b"RMC\\x02"  (version 2: signed; version 1 datagrams are refused)
    4       1     kind   (:class:`~.radio.DatagramKind`)
    5       1     link id: which radio of the sender (0: its only one)
    6       6     timestamp: 10 µs units since 2015-01-01 UTC, as MAVLink's
    12      1     n: length of the sender's name
    13      n     sender: ``ground`` or the robot's agent name (UTF-8)
    13+n    ...   payload (a beacon: none; a barrier signal: a serialized rosmc/BarrierSignal)
    end-8   8     signature: HMAC-SHA256(key, every byte before it), first 8 bytes

A receiver (:class:`Opener`) accepts a datagram only if its signature matches its own key
(compared with :func:`hmac.compare_digest`), it does not claim to come from the receiver
itself (a reflected datagram), and its timestamp is newer than the last one accepted from
the same (sender, link id). So a forged, altered, truncated or wrong-key datagram fails the
signature, and a recorded datagram played again (or overtaken by a newer one) fails the
timestamp. Only then does anything in it count: its kind, its payload, and the address it
came from (where the receiver sends to that sender next).

Why a wall-clock-seeded timestamp: only its order per sender matters, so hosts' clocks
need not agree. A sender stamps each datagram with its own clock, or with one more than its
last stamp if the clock has not moved or went back (:class:`Sealer`), so its stamps always
grow while it runs; and a sender that restarts starts from its clock again, which has moved
on meanwhile, so receivers that still remember it accept it at once — no state to keep on
disk, no handshake. A boot id with a counter would need the receiver to tell a new boot
from a replayed old one, which it cannot. The limits, said plainly: a sender whose clock is
set back across a restart is refused (counted, logged) until its clock passes its last
stamp again, or its receivers restart; and a receiver that restarts has no window yet, so
the first datagram it hears from each sender is taken as the newest (the sender's next one
settles it: an older recording can no longer pass once a newer datagram was heard).
"""

from __future__ import annotations

import calendar
import enum
import hmac
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from hashlib import sha256

from ..errors import RosmcError
from .radio import MAX_DATAGRAM, DatagramKind
from .radio_key import RadioKey

MAGIC = b"RMC\x02"
SIGNATURE_BYTES = 8  # 64 bits: a forger's chance per datagram is 2**-64
STAMP_BYTES = 6
STAMP_UNIT = 1e-5  # seconds per timestamp tick (MAVLink's)
STAMP_EPOCH = calendar.timegm((2015, 1, 1, 0, 0, 0))  # MAVLink's: 2**48 ticks last 89 years
MAX_NAME = 64
_HEAD = len(MAGIC) + 1 + 1 + STAMP_BYTES + 1  # up to the sender's name
OVERHEAD = _HEAD + SIGNATURE_BYTES  # bytes a datagram carries beside its sender and payload


class Refusal(enum.Enum):
    """Why a datagram was dropped."""

    MALFORMED = "not a signed ROSMC radio datagram"
    FORGED = "its signature does not match this deployment's radio key"
    REFLECTED = "it claims to come from this end itself"
    REPLAYED = "it is no newer than one already heard from its sender (replayed or reordered)"


class DatagramRefused(RosmcError):
    """A datagram that must not be acted on, and why (:class:`Refusal`)."""

    def __init__(self, refusal: Refusal, sender: str = "") -> None:
        claim = f" claiming to come from {sender!r}" if sender else ""
        super().__init__(f"a radio datagram{claim} was dropped: {refusal.value}")
        self.refusal = refusal
        self.sender = sender


@dataclass(frozen=True)
class Opened:
    """A datagram that passed every check."""

    kind: DatagramKind
    sender: str
    link_id: int
    stamp: int
    payload: bytes


def _signature(secret: bytes, data: bytes) -> bytes:
    return hmac.new(secret, data, sha256).digest()[:SIGNATURE_BYTES]


def stamp_of(seconds: float) -> int:
    """A wall-clock time as a timestamp (10 µs ticks since 2015), clipped to 48 bits."""
    return max(0, min(int((seconds - STAMP_EPOCH) / STAMP_UNIT), (1 << 48) - 1))


@dataclass
class Sealer:
    """Signs this end's datagrams (thread-safe: beacons and signals leave from several threads).

    Args:
        key: The deployment's key.
        sender: This end's name (``ground`` or the agent name).
        link_id: Which radio of the sender this is (0 for the only one).
        clock: Wall-clock seconds (only this end's order matters: see the module docstring).
    """

    key: RadioKey
    sender: str
    link_id: int = 0
    clock: Callable[[], float] = time.time
    _last: int = 0
    _lock: threading.Lock = field(default_factory=threading.Lock, repr=False)

    def __post_init__(self) -> None:
        name = self.sender.encode("utf-8")
        if not 0 < len(name) <= MAX_NAME or not 0 <= self.link_id < 256:
            raise RosmcError(
                f"a radio sender's name takes 1 to {MAX_NAME} bytes, got {self.sender!r}"
            )

    def seal(self, kind: DatagramKind, payload: bytes = b"") -> bytes:
        """One signed datagram; RosmcError if it would not fit :data:`MAX_DATAGRAM` bytes."""
        name = self.sender.encode("utf-8")
        size = OVERHEAD + len(name) + len(payload)
        if size > MAX_DATAGRAM:
            raise RosmcError(
                f"a {kind.name.lower()} datagram holds at most {MAX_DATAGRAM} bytes, "
                f"this one {size}"
            )
        with self._lock:
            self._last = max(self._last + 1, stamp_of(self.clock()))
            stamp = self._last
        body = b"".join(
            (
                MAGIC,
                bytes((int(kind), self.link_id)),
                stamp.to_bytes(STAMP_BYTES, "big"),
                bytes((len(name),)),
                name,
                payload,
            )
        )
        return body + _signature(self.key.secret, body)


@dataclass
class Opener:
    """Checks datagrams heard by one end, and remembers each sender's newest timestamp.

    Used by one receiving thread. ``own`` is this end's name: a datagram claiming it is a
    reflection of what this end sent.
    """

    key: RadioKey
    own: str
    _window: dict[tuple[str, int], int] = field(default_factory=dict)

    def open(self, data: bytes) -> Opened:
        """The datagram's content; DatagramRefused if it must be dropped.

        The window moves only for a datagram that passed every check, so forged ones can
        never lock a genuine sender out.
        """
        sender, kind, link_id, stamp, payload = _parse(data)
        body, signature = data[:-SIGNATURE_BYTES], data[-SIGNATURE_BYTES:]
        if not hmac.compare_digest(_signature(self.key.secret, body), signature):
            raise DatagramRefused(Refusal.FORGED, sender)
        if sender == self.own:
            raise DatagramRefused(Refusal.REFLECTED, sender)
        if stamp <= self._window.get((sender, link_id), -1):
            raise DatagramRefused(Refusal.REPLAYED, sender)
        try:
            datagram_kind = DatagramKind(kind)
        except ValueError:  # signed by the team: a newer version's kind
            raise DatagramRefused(Refusal.MALFORMED, sender) from None
        self._window[(sender, link_id)] = stamp
        return Opened(datagram_kind, sender, link_id, stamp, payload)


def _parse(data: bytes) -> tuple[str, int, int, int, bytes]:
    """sender, kind, link id, stamp and payload of a datagram (not yet authenticated)."""
    if len(data) < OVERHEAD + 1 or not data.startswith(MAGIC):
        raise DatagramRefused(Refusal.MALFORMED)
    kind, link_id = data[4], data[5]
    stamp = int.from_bytes(data[6 : 6 + STAMP_BYTES], "big")
    size = data[_HEAD - 1]
    end = _HEAD + size
    if not 0 < size <= MAX_NAME or end > len(data) - SIGNATURE_BYTES:
        raise DatagramRefused(Refusal.MALFORMED)
    try:
        sender = data[_HEAD:end].decode("utf-8")
    except UnicodeDecodeError:
        raise DatagramRefused(Refusal.MALFORMED) from None
    return sender, kind, link_id, stamp, data[end:-SIGNATURE_BYTES]
