"""An operator in another network namespace, driven from the test process.

The multi-host test's ROS graph lives in network namespaces that the test process cannot
reach, so its operator runs as a process on the ground (``python -m
tests.integration.remote_operator`` inside the ground namespace) around an
:class:`~tests.integration.executor_fixtures.Operator`. The test sends one JSON line per
call on the process's stdin (``{"method": ..., "args": [...]}``) and reads one JSON line
back: ``{"result": ..., "seconds": ...}`` or ``{"error": ..., "seconds": ...}``, where
``seconds`` is how long the call took in the operator (what an operator waits). A method
named ``module:function`` calls ``function(operator, *args)`` (how a benchmark runs its
measurements next to the server, e.g. ``bench.bench_executor:sync_to_start``).

:class:`RemoteOperator` is the test's end: ``remote.call("add", "r1", "wait", {...})``.
"""

from __future__ import annotations

import functools
import importlib
import json
import os
import queue
import subprocess
import sys
import threading
import time
import traceback
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import IO, Any

REPO_ROOT = Path(__file__).resolve().parents[2]


@dataclass(frozen=True)
class Answer:
    """What one remote call returned and how long the operator waited for it."""

    result: Any
    seconds: float


class RemoteError(AssertionError):
    """The remote operator's call raised (the message holds its traceback's last line)."""


class RemoteOperator:
    """The test's end of a remote operator process.

    Args:
        argv: The command that starts the remote side (in the ground's namespace).
        env: Its environment (``ROS_MASTER_URI``, ``ROS_IP`` of the ground).
        log_path: Where the remote side's stderr (its ROS logging) goes.
    """

    def __init__(self, argv: Sequence[str], env: Mapping[str, str], log_path: Path) -> None:
        log_path.parent.mkdir(parents=True, exist_ok=True)
        self.log_path = log_path
        with log_path.open("ab") as log:
            self.process = subprocess.Popen(
                list(argv),
                env=dict(env),
                cwd=REPO_ROOT,
                stdin=subprocess.PIPE,
                stdout=subprocess.PIPE,
                stderr=log,
                start_new_session=True,
                text=True,
            )
        self._lines: queue.Queue[str] = queue.Queue()
        reader = threading.Thread(target=self._read, daemon=True)
        reader.start()

    def _read(self) -> None:
        assert self.process.stdout is not None
        for line in self.process.stdout:
            self._lines.put(line)
        self._lines.put("")  # the process ended

    def call(self, method: str, *args: Any, timeout: float = 60.0) -> Answer:
        """Run ``method(*args)`` in the remote operator; wait at most ``timeout`` seconds."""
        assert self.process.stdin is not None
        self.process.stdin.write(json.dumps({"method": method, "args": list(args)}) + "\n")
        self.process.stdin.flush()
        try:
            line = self._lines.get(timeout=timeout)
        except queue.Empty:
            raise AssertionError(f"remote operator: no answer to {method} in {timeout} s") from None
        if not line:
            raise AssertionError(f"remote operator ended during {method}; see {self.log_path}")
        reply = json.loads(line)
        if "error" in reply:
            raise RemoteError(f"remote operator {method}{tuple(args)!r}: {reply['error']}")
        return Answer(reply["result"], float(reply["seconds"]))

    def __call__(self, method: str, *args: Any, timeout: float = 60.0) -> Any:
        """``call(...).result``."""
        return self.call(method, *args, timeout=timeout).result

    def close(self) -> None:
        """End the remote side (closing its stdin ends it; killed if it lingers)."""
        if self.process.stdin is not None:
            self.process.stdin.close()
        try:
            self.process.wait(10.0)
        except subprocess.TimeoutExpired:
            self.process.kill()
            self.process.wait(10.0)


# -- the remote side -----------------------------------------------------------------------
def _methods(operator: Any) -> dict[str, Callable[..., Any]]:
    """What the test may call: the operator's actions, answers made JSON-friendly."""
    import rosmc.msg as wire

    from rosmc_server.core import MissionState, SkillStatus

    def statuses(state: MissionState) -> dict[str, list[Any]]:
        return {s.id: [s.status.name, s.attempt, s.agent] for s in state.skills()}

    def wait_status(ids: list[str], status: str, timeout: float) -> dict[str, list[Any]]:
        return statuses(operator.wait_status(ids, SkillStatus[status], timeout))

    def wait_started(ids: list[str], timeout: float) -> dict[str, float]:
        """Wait until each skill has a start stamp (kept once it started, whatever it
        does next); the stamps."""
        state = operator.wait_mission(
            lambda m: all(m.skill(i).started > 0.0 for i in ids), timeout, f"{ids} to start"
        )
        return {i: state.skill(i).started for i in ids}

    def links(agents: list[str]) -> dict[str, str]:
        names = {wire.LinkState.UNKNOWN: "UNKNOWN", wire.LinkState.UP: "UP", 2: "DOWN"}
        return {a: names[operator.agent_state(a).link.state] for a in agents}

    return {
        "add": operator.add,
        "edit": operator.edit,
        "sync": operator.sync,
        "start": operator.start,
        "add_barrier": operator.add_barrier,
        "wait_links": operator.wait_links,
        "wait_status": wait_status,
        "wait_started": wait_started,
        "statuses": lambda: statuses(operator.mission()),
        "started": lambda: {s.id: s.started for s in operator.mission().skills()},
        "links": links,
        "waiting_on": lambda agent: operator.agent_state(agent).waiting_on,
        "barrier_wait": lambda agent: operator.agent_state(agent).barrier_wait,
        "revision": lambda: operator.mission().revision,
    }


def _resolve(methods: Mapping[str, Callable[..., Any]], name: str, operator: Any) -> Any:
    if ":" not in name:
        return methods[name]
    module, _, function = name.partition(":")
    measure = getattr(importlib.import_module(module), function)
    return functools.partial(measure, operator)


def _serve(operator: Any, requests: IO[str], replies: IO[str]) -> None:
    methods = _methods(operator)
    for line in requests:
        request = json.loads(line)
        began = time.monotonic()
        try:
            reply = {"result": _resolve(methods, request["method"], operator)(*request["args"])}
        except Exception as error:  # reported to the test, which fails with it
            traceback.print_exc()
            reply = {"error": f"{type(error).__name__}: {error}"}
        reply["seconds"] = time.monotonic() - began
        replies.write(json.dumps(reply) + "\n")
        replies.flush()


def main() -> int:
    """Serve calls from stdin until it closes."""
    replies = os.fdopen(os.dup(sys.stdout.fileno()), "w")
    os.dup2(sys.stderr.fileno(), sys.stdout.fileno())  # ROS logging must not mix with replies
    from tests.integration.executor_fixtures import Operator

    _serve(Operator(timeout=30.0), sys.stdin, replies)
    return 0


if __name__ == "__main__":
    sys.exit(main())
