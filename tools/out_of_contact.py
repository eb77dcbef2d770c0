"""Put a robot out of contact with work waiting for it, for the screenshot tools.

The simulator restores a blacked-out link of a robot inside Wi-Fi coverage, so the robot
itself falls silent instead: its executor gets SIGSTOP (as a robot out of radio range) and
SIGCONT after the picture. Once the server calls the link down, the operator sends the
robot's blueprint and a new lost-link policy; both wait for contact.
"""

from __future__ import annotations

import os
import signal
import xmlrpc.client


def silence_executor(agent: str, caller: str) -> int:
    """SIGSTOP ``agent``'s mission executor (``/<agent>/mission_executor``); its pid."""
    import rosgraph
    import rosnode

    uri = rosnode.get_api_uri(rosgraph.Master(caller), f"/{agent}/mission_executor")
    _code, _text, pid = xmlrpc.client.ServerProxy(uri).getPid(caller)
    os.kill(int(pid), signal.SIGSTOP)
    return int(pid)


def resume_executor(pid: int) -> None:
    """Let a silenced executor go on (SIGCONT)."""
    if pid:
        os.kill(pid, signal.SIGCONT)


def send_waiting_work(client: object, agent: str) -> None:
    """Synchronize ``agent``'s blueprint and change its lost-link policy (both will wait)."""
    from rosmc_server.core import LostLinkKind, LostLinkPolicy

    client.synchronize(agent)  # type: ignore[attr-defined]
    client.set_lost_link_policy(agent, LostLinkPolicy(LostLinkKind.HOLD, 60.0))  # type: ignore[attr-defined]
