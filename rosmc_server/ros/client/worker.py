"""The client without waiting: calls run on a worker thread and answer by callback or future.

GUIs must never wait on the network on their own thread (the server may be slow, gone or
restarting). :class:`AsyncMissionClient` runs every call on one worker thread, in the
order submitted (so an edit made after an add is sent after it), and hands back a
:class:`concurrent.futures.Future` and, if given, calls ``on_done`` with an
:class:`Outcome`: the value, or the error as one readable sentence.
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable
from concurrent.futures import Future, ThreadPoolExecutor
from dataclasses import dataclass
from typing import Generic, TypeVar

from ...core import RosmcError
from .mission_client import MissionClient

_log = logging.getLogger(__name__)

T = TypeVar("T")


@dataclass(frozen=True)
class Outcome(Generic[T]):
    """How a call ended: ``value`` on success, else ``error`` (a core error)."""

    value: T | None = None
    error: RosmcError | None = None

    @property
    def ok(self) -> bool:
        """The call succeeded."""
        return self.error is None


OnDone = Callable[[Outcome[T]], None]


class AsyncMissionClient:
    """A :class:`MissionClient` whose calls run on a worker thread; nothing here blocks.

    ``submit(lambda client: client.add_skill("drone", "take_off"), on_done)`` returns at
    once. ``on_done`` runs on the worker thread (a Qt GUI turns it into a signal); a
    failure reaches it as :attr:`Outcome.error`, and an unexpected exception (a bug) as a
    :class:`RosmcError` saying so, logged with its traceback. Calls run one at a time in
    submission order.

    Args:
        client: The client to call through (owned from now on: closed by :meth:`close`).
        name: Name of the worker thread (shows in tracebacks and debuggers).
    """

    def __init__(self, client: MissionClient, name: str = "rosmc-client") -> None:
        self.client = client
        self._executor = ThreadPoolExecutor(max_workers=1, thread_name_prefix=name)
        self._pending = 0
        self._lock = threading.Lock()

    @property
    def pending(self) -> int:
        """Calls submitted and not finished yet (a GUI may show "working...")."""
        with self._lock:
            return self._pending

    def submit(
        self,
        call: Callable[[MissionClient], T],
        on_done: Callable[[Outcome[T]], None] | None = None,
        seen: int | None = None,
    ) -> Future[T]:
        """Run ``call(client)`` on the worker; its result or error reaches ``on_done``.

        ``seen``: the mission revision the operator saw when asking; the client makes the
        call's mutating requests against it (see :meth:`MissionClient.against`).
        """
        with self._lock:
            self._pending += 1
        return self._executor.submit(self._run, call, on_done, seen)

    def close(self, wait: bool = False) -> None:
        """Stop taking calls; calls not started are dropped. Closes the connections."""
        self._executor.shutdown(wait=wait, cancel_futures=True)
        self.client.close()

    def _run(
        self,
        call: Callable[[MissionClient], T],
        on_done: Callable[[Outcome[T]], None] | None,
        seen: int | None,
    ) -> T:
        try:
            with self.client.against(seen):
                value = call(self.client)
        except RosmcError as error:
            self._finish(on_done, Outcome(error=error))
            raise
        except Exception as error:  # a bug must reach the caller as a sentence, not vanish
            _log.exception("a client call failed unexpectedly")
            wrapped = RosmcError(
                f"the client failed unexpectedly ({type(error).__name__}: {error})"
            )
            self._finish(on_done, Outcome(error=wrapped))
            raise wrapped from error
        self._finish(on_done, Outcome(value=value))
        return value

    def _finish(self, on_done: OnDone[T] | None, outcome: Outcome[T]) -> None:
        with self._lock:
            self._pending -= 1
        if on_done is None:
            return
        try:
            on_done(outcome)
        except Exception:  # the callback's own failure must not look like the call's
            _log.exception("a client callback failed")
