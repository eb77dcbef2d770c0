"""Which live nodes use given topic and service names on the ROS graph.

The master keeps a node's registrations until the node unregisters, so a node killed
(a crashed mission server, ``kill -9``) or still shutting down stays listed as the
publisher of its topics. A replay that refused to play over such a ghost would need
``rosnode cleanup`` first; :func:`taken_names` asks each listed node itself (its XML-RPC
``getPid``, as ``rosnode ping`` does) and counts only those that answer.
"""

from __future__ import annotations

import http.client
import xmlrpc.client
from collections.abc import Sequence

import rosgraph

from ..core.errors import ServerUnavailable

PING_TIMEOUT = 2.0
"""Seconds a listed node has to answer before its registration counts as stale."""


def taken_names(names: Sequence[str], caller_id: str = "/rosmc_replay") -> dict[str, list[str]]:
    """The live nodes publishing each of the topics, or serving each of the services, in
    ``names``.

    Names nobody (alive) uses are left out.

    Raises:
        ServerUnavailable: The ROS master does not answer.
    """
    master = rosgraph.Master(caller_id)
    try:
        publishers, _, services = master.getSystemState()
    except (OSError, rosgraph.MasterException) as err:
        raise ServerUnavailable(
            f"no ROS master answers at {rosgraph.get_master_uri()} ({err}); start roscore first"
        ) from err
    wanted = set(names)
    listed = {name: nodes for name, nodes in [*publishers, *services] if name in wanted and nodes}
    alive = {node: _answers(master, node) for nodes in listed.values() for node in nodes}
    taken = {name: sorted(n for n in nodes if alive[n]) for name, nodes in listed.items()}
    return {name: nodes for name, nodes in taken.items() if nodes}


def _answers(master: rosgraph.Master, node: str) -> bool:
    """Whether ``node`` answers at the address the master has for it."""
    try:
        uri = master.lookupNode(node)
    except (OSError, rosgraph.MasterException):
        return False  # the master no longer knows it
    try:
        xmlrpc.client.ServerProxy(uri, transport=_TimedTransport()).getPid(master.caller_id)
    except (OSError, http.client.HTTPException, xmlrpc.client.Error):
        return False
    return True


class _TimedTransport(xmlrpc.client.Transport):
    """An XML-RPC transport whose connections give up after :data:`PING_TIMEOUT`."""

    def make_connection(self, host: tuple[str, dict[str, str]] | str) -> http.client.HTTPConnection:
        connection = super().make_connection(host)
        connection.timeout = PING_TIMEOUT
        return connection
