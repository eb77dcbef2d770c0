"""Joining the ROS graph under a fixed name without shutting down a stranger.

rosmaster remembers a node by its name and the URI of its XML-RPC server. A node
killed with -9 (or by a power cut) stays registered. When a node of the same name
registers later, the master sends ``shutdown`` to the old URI, and the rospy node
listening there stops without checking that the message was meant for it. If the
operating system has meanwhile given that ephemeral port to another process, that
process is the one shut down, e.g. a robot's executor dying with "new node registered
with same name" because the ground's mission server respawned.

:func:`join_graph` therefore looks at the old registration of its name first, as
``rosnode cleanup`` does by hand. If nothing answers at the old URI, or what answers
does not publish and subscribe what the master holds for that name, the old entries are
unregistered, so the master forgets the name and sends no shutdown. A live node of the
same name is left alone: the ROS rule that the newer node replaces the older still holds.
"""

from __future__ import annotations

import logging
import xmlrpc.client
from collections.abc import Iterable
from typing import cast

import rosgraph
import rosgraph.names
import rospy
import rospy.core
import rospy.names

from .logging_bridge import ROSOUT_FLAG

_log = logging.getLogger(__name__)

# How long the node at a stale URI may take to answer; a silent one counts as gone.
PROBE_TIMEOUT = 2.0
# The parameters a ROSMC node subscribes to (rospy's parameter cache); the master keeps a
# name registered while any subscription of it remains.
SUBSCRIBED_PARAMS = (ROSOUT_FLAG,)

Registrations = tuple[list[str], list[str], list[str]]


def resolved_node_name(name: str) -> str:
    """The graph name ``rospy.init_node(name)`` will take (``__name`` and namespace applied)."""
    base = rospy.names.get_mappings().get("__name", name)
    return str(rosgraph.names.resolve_name(base, rospy.core.get_caller_id()))


def join_graph(name: str, **init_args: object) -> str:
    """``rospy.init_node(name, **init_args)`` after clearing a stale registration of the name.

    Returns the node's resolved name. Anonymous nodes take a new name each time and
    need none of this; call ``rospy.init_node`` for them.
    """
    clear_stale_registration(resolved_node_name(name))
    rospy.init_node(name, **init_args)
    return str(rospy.get_name())


def clear_stale_registration(node: str, master: rosgraph.Master | None = None) -> bool:
    """Unregister ``node``'s entries if its registered URI no longer belongs to it.

    Returns True when stale entries were removed. A master that cannot be reached is
    left to ``rospy.init_node``, which waits for it and says so.
    """
    master = master or rosgraph.Master(node)
    try:
        uri = str(master.lookupNode(node))
        registrations = _registrations_of(master, node)
    except rosgraph.MasterError:
        return False  # the name is not registered: nothing to clear
    except OSError:
        return False
    if _answers_as(uri, node, registrations):
        return False
    _unregister(rosgraph.Master(node), uri, registrations)
    _log.warning(
        "%s was still registered at %s, where that node no longer runs; its entries were "
        "removed so that the master does not shut down whatever listens there now",
        node,
        uri,
    )
    return True


def node_running(node: str, master: rosgraph.Master | None = None) -> bool:
    """Whether the master knows ``node`` and the process at its URI answers as a ROS node.

    A node killed with -9 stays registered; only an answer tells that it runs.
    """
    master = master or rosgraph.Master(rospy.get_name())
    try:
        uri = str(master.lookupNode(node))
    except (rosgraph.MasterError, OSError):
        return False
    proxy = _node_api(uri)
    try:
        code, _message, _pid = cast(tuple[int, str, int], proxy.getPid(master.caller_id))
    except (OSError, xmlrpc.client.Error):
        return False
    return code == 1


def _registrations_of(master: rosgraph.Master, node: str) -> Registrations:
    """The topics ``node`` publishes and subscribes and the services it offers, per the master."""
    publishers, subscribers, services = master.getSystemState()
    return (
        _names_with(node, publishers),
        _names_with(node, subscribers),
        _names_with(node, services),
    )


def _names_with(node: str, entries: Iterable[tuple[str, list[str]]]) -> list[str]:
    return [name for name, nodes in entries if node in nodes]


def _answers_as(uri: str, node: str, registrations: Registrations) -> bool:
    """Whether the process at ``uri`` publishes and subscribes what the master holds for ``node``.

    Services cannot be asked of a node, so topics decide; every ROSMC node with a fixed
    name has some. With none registered the answer is yes, so nothing is removed.
    """
    published, subscribed, _services = registrations
    proxy = _node_api(uri)
    try:
        their_publications = _topics(proxy.getPublications(node))
        their_subscriptions = _topics(proxy.getSubscriptions(node))
    except (OSError, xmlrpc.client.Error):
        return False  # nobody there, or not a ROS node
    return set(published) <= their_publications and set(subscribed) <= their_subscriptions


def _topics(answer: object) -> set[str]:
    """The topic names of a slave API ``[code, message, [[topic, type], ...]]`` answer."""
    code, _message, pairs = cast(tuple[int, str, list[list[str]]], answer)
    return {pair[0] for pair in pairs} if code == 1 else set()


def _unregister(master: rosgraph.Master, uri: str, registrations: Registrations) -> None:
    """Remove every entry of the stale node, so the master drops the name."""
    published, subscribed, services = registrations
    for topic in published:
        master.unregisterPublisher(topic, uri)
    for topic in subscribed:
        master.unregisterSubscriber(topic, uri)
    for service in services:
        try:
            master.unregisterService(service, master.lookupService(service))
        except rosgraph.MasterError:
            continue  # taken over or gone since getSystemState
    for key in SUBSCRIBED_PARAMS:
        master.unsubscribeParam(uri, key)


def _node_api(uri: str) -> xmlrpc.client.ServerProxy:
    """The node API at ``uri``, giving up after :data:`PROBE_TIMEOUT` (a silent node is gone)."""
    return xmlrpc.client.ServerProxy(uri, transport=_TimedTransport(PROBE_TIMEOUT))


class _TimedTransport(xmlrpc.client.Transport):
    """An XML-RPC transport whose connection gives up after ``timeout`` seconds."""

    def __init__(self, timeout: float) -> None:
        super().__init__()
        self._timeout = timeout

    def make_connection(self, host: object) -> object:  # type: ignore[override]
        connection = super().make_connection(host)  # type: ignore[arg-type]
        connection.timeout = self._timeout
        return connection


__all__ = ["clear_stale_registration", "join_graph", "node_running", "resolved_node_name"]
