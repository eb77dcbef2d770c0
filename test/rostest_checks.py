"""What the rostest check nodes share: start-up, waiting, and the client they use.

The check nodes in this folder are started by the ``.test`` files here (``rostest rosmc
server.test``) with rostest's own master and runner; each is a ``unittest`` case that talks
to the real nodes the ``.test`` file launched.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import TypeVar

T = TypeVar("T")

DEADLINE = 60.0  # seconds; the .test files' time-limit is larger


def wait_for(what: str, probe: Callable[[], T | None], timeout: float = DEADLINE) -> T:
    """Poll ``probe`` until it returns something other than None/False; fail after ``timeout``."""
    end = time.monotonic() + timeout
    while True:
        value = probe()
        if value is not None and value is not False:
            return value
        if time.monotonic() > end:
            raise AssertionError(f"timed out after {timeout:.0f} s waiting for {what}")
        time.sleep(0.1)


def statuses(client: object, agent: str) -> list[str]:
    """Status names of ``agent``'s skills, in task order."""
    state = client.get_mission()  # type: ignore[attr-defined]
    return [skill.status.name for skill in state.task(agent)]
