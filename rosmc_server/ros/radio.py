"""The robot link's UDP side channel: beacons and barrier signals (see :mod:`..core.radio`).

Each end (the mission server as ``ground``, each executor under its agent name) binds one
UDP socket, on every address and an ephemeral port unless ``port`` is given, and registers
``host:port`` on the parameter server as ``/rosmc/radio/<name>`` (``host`` as ROS_IP or
ROS_HOSTNAME give it, like every other address a node advertises). A background thread
reads that directory through the master with a timeout, so a cut radio never blocks
anything else: every :data:`~..core.radio.DIRECTORY_PERIOD` seconds after a change, less
often while it stays the same (:func:`~..core.radio.next_directory_period`), and at once
when asked (:meth:`Radio.refresh`); the address a datagram came from counts too (the
newest wins).

:class:`TopicListener` is a subscriber that can be reconnected: when a beacon shows a
peer is back after a silence, the link's subscribers for it connect afresh at once,
instead of waiting for TCP's next retransmission of the stalled connection.
"""

from __future__ import annotations

import logging
import socket
import threading
import time
import xmlrpc.client
from collections.abc import Callable, Iterable
from io import BytesIO
from typing import Any

import rosgraph
import rosgraph.network
import rosmc.msg as wire
import rospy

from ..core import RosmcError
from ..core.radio import (
    DIRECTORY_PERIOD,
    DatagramKind,
    decode_datagram,
    encode_datagram,
    next_directory_period,
    parse_endpoint,
)
from ..interface import RADIO_DIRECTORY
from .connections import TimeoutTransport

_log = logging.getLogger(__name__)
MASTER_TIMEOUT = 2.0  # seconds an XML-RPC call to the master may take
GROUND = "ground"


class Radio:
    """One end of the side channel.

    Args:
        name: ``ground`` or the agent's name.
        on_beacon: Called with the sender's name for each beacon, and whether it was a
            return beacon (on the receive thread).
        on_signal: Called with each barrier signal heard (on the receive thread).
        port: UDP port to bind (0: any free one).
    """

    def __init__(
        self,
        name: str,
        on_beacon: Callable[[str, bool], None],
        on_signal: Callable[[wire.BarrierSignal], None] | None = None,
        port: int = 0,
    ) -> None:
        self.name = name
        self._on_beacon = on_beacon
        self._on_signal = on_signal
        self._socket = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self._socket.bind(("0.0.0.0", port))
        self._socket.settimeout(0.5)
        host = rosgraph.network.get_host_name()
        self.endpoint = f"{host}:{self._socket.getsockname()[1]}"
        self._addresses: dict[str, tuple[str, int]] = {}  # where to send, by name
        self._listed: dict[str, tuple[str, int]] = {}  # as last read from the directory
        self._lock = threading.Lock()
        self._closed = threading.Event()
        self._wake = threading.Event()  # read the directory now
        self._last_read = float("-inf")  # monotonic time of the last read of the directory
        self._registered = False
        self._master = xmlrpc.client.ServerProxy(
            rosgraph.get_master_uri(), transport=TimeoutTransport(MASTER_TIMEOUT)
        )
        self._threads = [
            threading.Thread(target=self._receive, name=f"radio-{name}-rx", daemon=True),
            threading.Thread(target=self._directory, name=f"radio-{name}-dir", daemon=True),
        ]
        for thread in self._threads:
            thread.start()

    # -- sending ------------------------------------------------------------------------
    def beacon(self, peer: str, kind: DatagramKind = DatagramKind.BEACON) -> None:
        """Tell ``peer`` this end is here (nothing if its address is not known yet).

        ``kind`` is BEACON or RETURN_BEACON (this end does not hear ``peer``, or just did
        again after a silence).
        """
        self._send(peer, encode_datagram(kind, self.name.encode("utf-8")))

    def signal(self, msg: wire.BarrierSignal, peers: Iterable[str]) -> None:
        """Send a barrier signal to each of ``peers`` whose address is known."""
        buffer = BytesIO()
        msg.serialize(buffer)
        data = encode_datagram(DatagramKind.BARRIER_SIGNAL, buffer.getvalue())
        for peer in peers:
            self._send(peer, data)

    def robots(self) -> list[str]:
        """Every other end known but the ground: the robots' executors."""
        with self._lock:
            return [n for n in self._addresses if n not in (self.name, GROUND)]

    def _send(self, peer: str, data: bytes) -> None:
        with self._lock:
            address = self._addresses.get(peer)
        if address is None:
            return
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
            kind, payload = decode_datagram(data)
            if kind in (DatagramKind.BEACON, DatagramKind.RETURN_BEACON):
                sender = payload.decode("utf-8")
                self._learn(sender, source)
                self._on_beacon(sender, kind is DatagramKind.RETURN_BEACON)
                return
            msg = wire.BarrierSignal()
            msg.deserialize(payload)
        except (RosmcError, UnicodeDecodeError, ValueError) as error:
            _log.debug("radio %s: ignoring a datagram from %s: %s", self.name, source, error)
            return
        except Exception as error:  # genpy raises struct.error and others on short input
            _log.debug(
                "radio %s: ignoring a malformed signal from %s: %s", self.name, source, error
            )
            return
        self._learn(msg.agent, source)
        if self._on_signal is not None:
            self._on_signal(msg)

    def _learn(self, name: str, source: tuple[str, int]) -> None:
        if name and name != self.name:
            with self._lock:
                self._addresses[name] = source

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
                # A new entry (a restarted peer) wins; an unchanged one does not override
                # where the peer was last heard from.
                if self._listed.get(name) != address:
                    self._listed[name] = address
                    self._addresses[name] = address
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
