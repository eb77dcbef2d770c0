"""Whether a subscriber's publishers count its connection yet.

A rospy subscriber counts a connection as soon as the publisher's header arrives; the
publisher adds it to the connections it writes to a moment later. A message published in
between never reaches that subscriber. Most topics repeat what they say, but an action
server that finishes a goal at once publishes its one result in that window, and the
client then waits for it for ever. Asking the publishing node (its XML-RPC
``getBusInfo``, as ``rosnode info`` does) closes the window.
"""

from __future__ import annotations

import xmlrpc.client
from http.client import HTTPConnection
from typing import Any

import rospy

CALL_TIMEOUT = 2.0
"""Seconds a publisher's node may take to answer."""


class TimeoutTransport(xmlrpc.client.Transport):
    """XML-RPC over HTTP whose connections time out (rospy's own calls never do)."""

    def __init__(self, timeout: float) -> None:
        super().__init__()
        self._timeout = timeout

    def make_connection(self, host: Any) -> HTTPConnection:
        """An HTTP connection that gives up after the timeout."""
        connection = super().make_connection(host)
        connection.timeout = self._timeout
        return connection


def publishers_count_me(subscriber: rospy.Subscriber) -> bool:
    """Whether every publisher ``subscriber`` is connected to writes to it already.

    False while it has no connection, or while a publisher's node does not list the
    connection (or does not answer within :data:`CALL_TIMEOUT`).
    """
    topic, me = subscriber.resolved_name, rospy.get_name()
    connections = list(subscriber.impl.connections)
    if not connections:
        return False
    for connection in connections:
        node = xmlrpc.client.ServerProxy(
            connection.endpoint_id, transport=TimeoutTransport(CALL_TIMEOUT)
        )
        try:
            answer: Any = node.getBusInfo(me)
        except (OSError, xmlrpc.client.Error):
            return False
        bus = answer[2] if answer[0] == 1 else []
        if not any(row[1] == me and row[2] == "o" and row[4] == topic for row in bus):
            return False
    return True
