"""The robot link's UDP side channel: beacons and barrier signals (see :mod:`..core.radio`).

Each end (the mission server as ``ground``, each executor under its agent name) binds one
UDP socket, on every address and an ephemeral port unless ``port`` is given, and registers
``host:port`` on the parameter server as ``/rosmc/radio/<name>`` (``host`` as ROS_IP or
ROS_HOSTNAME give it, like every other address a node advertises). A background thread
reads that directory through the master with a timeout, so a cut radio never blocks
anything else: every :data:`~..core.radio.DIRECTORY_PERIOD` seconds after a change, less
often while it stays the same (:func:`~..core.radio.next_directory_period`), and at once
when asked (:meth:`Radio.refresh`).

Every datagram is signed with the deployment's key and checked on arrival
(:mod:`..core.radio_auth`); one that fails is dropped, counted (:attr:`Radio.dropped`) and
logged at a limited rate (:class:`~..core.drop_log.DropLog`), never acted on. Anyone can
write the parameter server, so the directory is only a hint: a peer's address is where an
authenticated datagram of its own last came from, and a datagram for it also goes to the
addresses the directory listed for it since (the newest only, once the peer was heard): a
peer that restarted on another port is reached that way until it speaks, and a forged entry
only ever gets copies it can neither alter nor play back, while the peer itself writes its
entry back at its next read of the directory.

:class:`TopicListener` is a subscriber that can be reconnected: when a beacon shows a
peer is back after a silence, the link's subscribers for it connect afresh at once,
instead of waiting for TCP's next retransmission of the stalled connection.
"""

from __future__ import annotations

import logging
import os
import socket
import threading
import time
import xmlrpc.client
from collections.abc import Callable, Iterable
from io import BytesIO
from pathlib import Path
from typing import Any

import rosgraph
import rosgraph.network
import rosmc.msg as wire
import rospy

from ...core import RosmcError
from ...core.robots.drop_log import DropLog
from ...core.robots.radio import (
    DIRECTORY_PERIOD,
    DatagramKind,
    next_directory_period,
    parse_endpoint,
)
from ...core.robots.radio_auth import DatagramRefused, Opener, Sealer
from ...core.robots.radio_key import RadioKey, obtain_key
from ...interface import RADIO_DIRECTORY
from .connections import TimeoutTransport

_log = logging.getLogger(__name__)
MASTER_TIMEOUT = 2.0  # seconds an XML-RPC call to the master may take
GROUND = "ground"
MAX_HINTS = 4  # directory listings kept per peer until it is heard


def node_radio_key(path: str, who: str) -> RadioKey:
    """The key a node signs with: from ``path`` (its ``~radio_key``), else the default place.

    Raises RadioKeyError (one sentence naming the file and the fix) if it is unusable. A key
    made at the default place just now is announced: every other host needs a copy.
    """
    key, made = obtain_key(Path(path) if path else None, os.environ)
    if made:
        _log.warning(
            "%s: made a new radio key %s (fingerprint %s); every host of the deployment needs "
            "a copy of this file ('rosmc key show' prints a key's fingerprint)",
            who,
            key.path,
            key.fingerprint,
        )
    return key


class Radio:
    """One end of the side channel.

    Args:
        name: ``ground`` or the agent's name.
        on_beacon: Called with the sender's name for each beacon, and whether it was a
            return beacon (on the receive thread).
        on_signal: Called with each barrier signal heard (on the receive thread).
        port: UDP port to bind (0: any free one).
        key: The deployment's radio key: it signs what this end sends and checks what it hears.
    """

    def __init__(
        self,
        name: str,
        on_beacon: Callable[[str, bool], None],
        on_signal: Callable[[wire.BarrierSignal], None] | None = None,
        port: int = 0,
        *,
        key: RadioKey,
    ) -> None:
        self.name = name
        self._on_beacon = on_beacon
        self._on_signal = on_signal
        self._sealer = Sealer(key, name)
        self._opener = Opener(key, name)  # used by the receive thread only
        self._drops = DropLog("radio datagram")
        self._claimed: dict[str, int] = {}  # dropped datagrams by the sender they named
        self._socket = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self._socket.bind(("0.0.0.0", port))
        self._socket.settimeout(0.5)
        host = rosgraph.network.get_host_name()
        self.endpoint = f"{host}:{self._socket.getsockname()[1]}"
        self._heard: dict[str, tuple[str, int]] = {}  # where each peer's own datagrams came from
        # What the directory listed for each peer since it was last heard, newest last: hints
        # (someone may have overwritten the entry; its owner puts it right again).
        self._listed: dict[str, list[tuple[str, int]]] = {}
        self._lock = threading.Lock()
        self._send_lock = threading.Lock()  # datagrams leave in the order they were stamped
        self._closed = threading.Event()
        self._wake = threading.Event()  # read the directory now
        self._last_read = float("-inf")  # monotonic time of the last read of the directory
        self._registered = False
        self._master = xmlrpc.client.ServerProxy(
            rosgraph.get_master_uri(), transport=TimeoutTransport(MASTER_TIMEOUT)
        )
        _log.info(
            "radio %s: datagrams signed with the radio key %s (fingerprint %s)",
            name,
            key.path,
            key.fingerprint,
        )
        self._threads = [
            threading.Thread(target=self._receive, name=f"radio-{name}-rx", daemon=True),
            threading.Thread(target=self._directory, name=f"radio-{name}-dir", daemon=True),
        ]
        for thread in self._threads:
            thread.start()

    @property
    def dropped(self) -> int:
        """Datagrams dropped since start: unsigned, forged, replayed, reflected or unreadable."""
        with self._lock:
            return self._drops.total

    def dropped_from(self, sender: str) -> int:
        """Dropped datagrams that named ``sender`` (a claim: nothing proves who sent them)."""
        with self._lock:
            return self._claimed.get(sender, 0)

    # -- sending ------------------------------------------------------------------------
    def beacon(self, peer: str, kind: DatagramKind = DatagramKind.BEACON) -> None:
        """Tell ``peer`` this end is here (nothing if its address is not known yet).

        ``kind`` is BEACON or RETURN_BEACON (this end does not hear ``peer``, or just did
        again after a silence).
        """
        self._send([peer], kind, b"")

    def signal(self, msg: wire.BarrierSignal, peers: Iterable[str]) -> None:
        """Send a barrier signal to each of ``peers`` whose address is known."""
        buffer = BytesIO()
        msg.serialize(buffer)
        self._send(list(peers), DatagramKind.BARRIER_SIGNAL, buffer.getvalue())

    def robots(self) -> list[str]:
        """Every other end known but the ground: the robots' executors."""
        with self._lock:
            names = dict.fromkeys([*self._heard, *self._listed])
        return [n for n in names if n not in (self.name, GROUND)]

    def _targets(self, peer: str) -> list[tuple[str, int]]:
        with self._lock:
            heard = self._heard.get(peer)
            found = [*([heard] if heard is not None else []), *self._listed.get(peer, [])]
        return list(dict.fromkeys(found))

    def _send(self, peers: list[str], kind: DatagramKind, payload: bytes) -> None:
        targets = [(peer, address) for peer in peers for address in self._targets(peer)]
        if not targets:
            return
        with self._send_lock:
            data = self._sealer.seal(kind, payload)
            for peer, address in targets:
                try:
                    self._socket.sendto(data, address)
                except OSError as error:  # a radio that is down: the sender repeats anyway
                    _log.debug("radio %s: cannot send to %s: %s", self.name, peer, error)

    # -- receiving ----------------------------------------------------------------------
    def _receive(self) -> None:
        while not self._closed.is_set():
            try:
                data, source = self._socket.recvfrom(65535)
            except TimeoutError:
                continue
            except OSError:
                if self._closed.is_set():
                    return
                raise
            try:
                self._dispatch(data, source)
            except Exception:  # one bad datagram must never stop the receiver
                _log.exception("radio %s: failed to handle a datagram from %s", self.name, source)

    def _dispatch(self, data: bytes, source: tuple[str, int]) -> None:
        try:
            opened = self._opener.open(data)
        except DatagramRefused as refused:
            self._drop(refused.refusal.value, refused.sender, source)
            return
        msg: wire.BarrierSignal | None = None
        if opened.kind is DatagramKind.BARRIER_SIGNAL:
            msg = wire.BarrierSignal()
            try:
                msg.deserialize(opened.payload)
            except Exception as error:  # genpy raises struct.error and others on short input
                self._drop(f"its barrier signal cannot be read ({error})", opened.sender, source)
                return
            if msg.agent != opened.sender:
                self._drop(f"it speaks for {msg.agent!r}", opened.sender, source)
                return
        # Authenticated and fresh: only now does its address count.
        with self._lock:
            self._heard[opened.sender] = source
            hints = self._listed.get(opened.sender)
            if hints:
                del hints[:-1]  # the peer is found: older listings are of no more use
        if msg is None:
            self._on_beacon(opened.sender, opened.kind is DatagramKind.RETURN_BEACON)
        elif self._on_signal is not None:
            self._on_signal(msg)

    def _drop(self, reason: str, sender: str, source: tuple[str, int]) -> None:
        claim = f" naming {sender!r}" if sender else ""
        with self._lock:
            self._claimed[sender] = self._claimed.get(sender, 0) + 1
            warning = self._drops.drop(
                reason, f"from {source[0]}:{source[1]}{claim}", time.monotonic()
            )
        if warning is not None:
            _log.warning("radio %s: %s", self.name, warning)

    # -- the directory on the parameter server -------------------------------------------
    def refresh(self) -> None:
        """Read the directory soon (a peer may have moved), unless it was read just now."""
        if time.monotonic() - self._last_read > DIRECTORY_PERIOD:
            self._wake.set()

    def _directory(self) -> None:
        period = DIRECTORY_PERIOD
        while not self._closed.is_set():
            self._last_read = time.monotonic()
            try:
                changed = self._read_directory()
            except (OSError, xmlrpc.client.Error) as error:  # the master is out of reach
                _log.debug("radio %s: directory unavailable: %s", self.name, error)
                changed = True  # try again soon
            period = next_directory_period(period, changed)
            self._wake.wait(period)
            self._wake.clear()

    def _read_directory(self) -> bool:
        """Register this end and learn the others' endpoints; whether anything changed."""
        caller = rospy.get_name() if rospy.core.is_initialized() else f"/rosmc_radio_{self.name}"
        answer: Any = self._master.getParam(caller, RADIO_DIRECTORY)
        code, _, entries = answer
        entries = entries if code == 1 and isinstance(entries, dict) else {}
        changed = entries.get(self.name) != self.endpoint
        if changed:
            self._master.setParam(caller, f"{RADIO_DIRECTORY}/{self.name}", self.endpoint)
        for name, text in entries.items():
            if name == self.name or not isinstance(text, str):
                continue
            try:
                host, port = parse_endpoint(text)
                address = (socket.gethostbyname(host), port)
            except (RosmcError, OSError) as error:
                _log.debug("radio %s: skipping %s's endpoint: %s", self.name, name, error)
                continue
            with self._lock:
                # A hint only: datagrams for the peer also go there until the peer is heard
                # from it (a restarted peer's new port); what it says is never trusted.
                hints = self._listed.setdefault(name, [])
                if not hints or hints[-1] != address:
                    if address in hints:
                        hints.remove(address)
                    hints.append(address)
                    del hints[:-MAX_HINTS]
                    changed = True
        return changed

    def close(self) -> None:
        """Stop receiving and close the socket (the directory entry stays for a restart)."""
        self._closed.set()
        self._wake.set()
        self._socket.close()


class TopicListener:
    """A rospy subscriber that can be connected afresh (see the module docstring)."""

    def __init__(
        self, topic: str, data_class: type, callback: Callable[[Any], None], **options: Any
    ) -> None:
        self._args = (topic, data_class, callback)
        self._options = options
        self._lock = threading.Lock()
        self._subscriber = rospy.Subscriber(*self._args, **options)

    def reconnect(self) -> None:
        """Drop the connections and subscribe anew (this calls the master: not in a callback)."""
        with self._lock:
            self._subscriber.unregister()
            self._subscriber = rospy.Subscriber(*self._args, **self._options)

    def unregister(self) -> None:
        """Stop listening."""
        with self._lock:
            self._subscriber.unregister()


def reconnect_in_background(listeners: Iterable[TopicListener], why: str) -> None:
    """Reconnect ``listeners`` on a thread of their own (callers hold locks or run callbacks)."""
    chosen = list(listeners)

    def run() -> None:
        for listener in chosen:
            try:
                listener.reconnect()
            except (rospy.ROSException, OSError) as error:
                _log.warning("radio: could not reconnect a link topic (%s): %s", why, error)
        _log.info("radio: link topics reconnected: %s", why)

    threading.Thread(target=run, name="radio-reconnect", daemon=True).start()
