"""Connections to the operator services, and error codes turned back into core errors.

Services called: ``/rosmc/<operation>`` for each operation of
:data:`rosmc_server.interface.SERVICES` (types ``rosmc/<Name>``).
"""

from __future__ import annotations

import io
import logging
import socket
import threading
import time
from collections.abc import Mapping
from typing import Any

import genpy
import rosgraph
import rosgraph.network
import rosmc.srv as srv
import rospy
from rosmc.msg import ErrorCode
from rospy.exceptions import TransportException

from ... import interface
from ...conversions.task_memory import TaskMemory
from ...conversions.unpacking import remembering_get_mission
from ...core import (
    InvalidRequest,
    NotFound,
    NotPermitted,
    RosmcError,
    RuleViolation,
    Unavailable,
)
from ...core.errors import ServerUnavailable
from .results import RevisionConflict

_log = logging.getLogger(__name__)

_ERRORS: Mapping[int, type[RosmcError]] = {
    ErrorCode.INVALID: InvalidRequest,
    ErrorCode.NOT_FOUND: NotFound,
    ErrorCode.RULE: RuleViolation,
    ErrorCode.UNAVAILABLE: Unavailable,
    ErrorCode.INTERNAL: RosmcError,
    ErrorCode.FORBIDDEN: NotPermitted,
}
# rospy's ServiceException texts when the server's handler (not the connection) failed.
_HANDLER_FAILURES = ("service cannot process request", "error processing request")


class ServiceCaller:
    """Calls operator services over persistent connections, reconnecting when one breaks.

    A connection is opened on first use of a service, after waiting up to ``timeout``
    seconds for the service to appear. If a call fails because the connection broke
    (e.g. the server restarted), the client reconnects and sends the request once more;
    that is safe because every mutating request carries a base revision, so a request
    the old server already applied comes back as a conflict rather than applying twice.
    Calls are serialized by one lock, so one client can be shared between threads.
    """

    def __init__(self, timeout: float = 5.0, prefix: str = "") -> None:
        if timeout <= 0:
            raise ValueError("the timeout must be positive")
        self.timeout = timeout
        self.prefix = prefix
        self._proxies: dict[str, rospy.ServiceProxy] = {}
        self._lock = threading.RLock()
        # GetMission answers are read straight into core objects, not genpy messages,
        # reusing the skills of records unchanged since the last answer.
        self._answered_as = {"get_mission": remembering_get_mission(TaskMemory())}

    def close(self) -> None:
        """Close every persistent connection (they reopen on the next call)."""
        with self._lock:
            for operation in list(self._proxies):
                self._drop(operation)

    def call(self, operation: str, **fields: Any) -> Any:
        """Call the service of ``operation`` with a request made of ``fields``.

        Raises:
            InvalidRequest: the fields do not fit the request message.
            ServerUnavailable: the service did not answer within the timeout.
            RosmcError: the server's handler failed without an answer.
        """
        request = self._request(operation, fields)
        with self._lock:
            for attempt in (1, 2):
                proxy = self._proxy(operation)
                try:
                    return proxy.call(request)
                except (rospy.ServiceException, TransportException, OSError) as error:
                    self._drop(operation)
                    if str(error).startswith(_HANDLER_FAILURES):
                        raise RosmcError(f"the mission server failed in {operation}") from error
                    if attempt == 2:
                        raise ServerUnavailable(
                            f"the mission server stopped answering {operation} ({error})"
                        ) from error
                    _log.info("connection to %s broke (%s); reconnecting", operation, error)
        raise AssertionError("unreachable")  # pragma: no cover

    def _request(self, operation: str, fields: Mapping[str, Any]) -> Any:
        service_class = getattr(srv, interface.SERVICES[operation])
        try:
            request = service_class._request_class(**fields)
            request.serialize(io.BytesIO())  # fail here, not half-way into a connection
        except (genpy.SerializationError, TypeError, ValueError) as error:
            raise InvalidRequest(f"the {operation} request cannot be sent: {error}") from error
        return request

    def _proxy(self, operation: str) -> rospy.ServiceProxy:
        proxy = self._proxies.get(operation)
        if proxy is not None:
            return proxy
        name = interface.service_name(operation, self.prefix)
        deadline = time.monotonic() + self.timeout
        while not _service_answers(name, max(0.1, deadline - time.monotonic())):
            if time.monotonic() >= deadline or rospy.is_shutdown():
                raise ServerUnavailable(self._not_reachable(name))
            time.sleep(0.1)
        service_class = self._answered_as.get(operation) or getattr(
            srv, interface.SERVICES[operation]
        )
        proxy = rospy.ServiceProxy(name, service_class, persistent=True)
        self._proxies[operation] = proxy
        return proxy

    def _not_reachable(self, name: str) -> str:
        master = rosgraph.get_master_uri()
        if not rosgraph.is_master_online(master):
            return f"the ROS master at {master} is not reachable (is ROS_MASTER_URI right?)"
        return (
            f"the mission server is not reachable: {name} did not answer within "
            f"{self.timeout:g} s (ROS master {master})"
        )

    def _drop(self, operation: str) -> None:
        proxy = self._proxies.pop(operation, None)
        if proxy is not None:
            proxy.close()


def _service_answers(name: str, timeout: float) -> bool:
    """Whether the master knows service ``name`` and its server accepts a connection.

    Like ``rospy.wait_for_service``'s probe, but without rospy's logging, which
    needs an initialized node (and raises ROSInitException instead of waiting).
    """
    try:
        uri = rosgraph.Master(rospy.names.get_caller_id()).lookupService(name)
        address = rospy.core.parse_rosrpc_uri(uri)
        with socket.create_connection(address, timeout=timeout) as connection:
            caller = rospy.names.get_caller_id()
            header = {"probe": "1", "md5sum": "*", "callerid": caller, "service": name}
            rosgraph.network.write_ros_handshake_header(connection, header)
    except (rosgraph.MasterException, rospy.ROSException, OSError):
        return False
    return True


def raise_for(response: Any, base_revision: int) -> None:
    """Raise the core error that a refused response's error code stands for."""
    code = response.error_code
    if code == ErrorCode.NONE:
        return
    message = response.error or f"the mission server refused the request (error code {code})"
    if code == ErrorCode.CONFLICT:
        raise RevisionConflict(message, base_revision, response.revision)
    raise _ERRORS.get(code, RosmcError)(message)
