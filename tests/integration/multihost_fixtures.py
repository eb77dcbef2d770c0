"""A ROSMC team spread over the hosts of a :class:`~tests.integration.netns.RadioLab`.

:class:`LabSystem` is a :class:`~tests.integration.executor_fixtures.RosmcSystem` whose
processes run on the lab's hosts: ``rosmaster``, the mission server, the link emulator and
the operator on the ground, each robot's executor on its own host, every process with its
host's ``ROS_IP`` and ``ROS_MASTER_URI`` pointing at the ground. An executor can also be
started the way docs/integrator-guide.md tells a robot's owner to: ``source env.sh`` with only
``ROS_MASTER_URI`` set, then ``roslaunch rosmc executor.launch robot:=NAME``.

Used by ``tests/integration/test_multihost.py`` and ``bench/bench_multihost.py``. Not a test
module: pytest collects nothing here.
"""

from __future__ import annotations

import os
import shlex
import subprocess
import sys
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

from tests.integration.executor_fixtures import REPO_ROOT, RosmcSystem
from tests.integration.netns import GROUND, RadioLab
from tests.integration.remote_operator import RemoteOperator

MASTER_PORT = 11311  # every host has its own ports: the default cannot collide with anything
MASTER_START_TIMEOUT = 30.0

# Run inside a namespace: wait until the master answers (the test's own namespace cannot).
_WAIT_MASTER = """
import sys, time, xmlrpc.client
uri, deadline = sys.argv[1], time.monotonic() + float(sys.argv[2])
while time.monotonic() < deadline:
    try:
        if xmlrpc.client.ServerProxy(uri).getSystemState("/probe")[0] == 1:
            sys.exit(0)
    except OSError:
        pass
    time.sleep(0.1)
sys.exit(1)
"""


def lab_base_env(home: Path) -> dict[str, str]:
    """This process's environment for the lab's processes, with a private ``ROS_HOME``."""
    (home / "log").mkdir(parents=True, exist_ok=True)
    env = dict(os.environ)
    env.update(ROS_HOME=str(home), ROS_LOG_DIR=str(home / "log"), PYTHONUNBUFFERED="1")
    return env


@dataclass
class LabSystem(RosmcSystem):
    """Master, server, emulator and operator on the lab's ground; one executor per robot host."""

    lab: RadioLab | None = None
    operators: list[RemoteOperator] = field(default_factory=list)

    @property
    def radio(self) -> RadioLab:
        """The lab the system runs in."""
        assert self.lab is not None, "LabSystem needs a lab"
        return self.lab

    def host_of(self, name: str) -> str:
        """Where process ``name`` runs: a robot's executor on the robot, the rest on the ground."""
        return name if name in self.radio.robots else GROUND

    def _start(self, name: str, argv: Sequence[str], env: Mapping[str, str] | None = None) -> None:
        host = self.host_of(name)
        env = self.radio.environment(host, env or self.env, MASTER_PORT)
        super()._start(name, self.radio.command(host, argv), env)

    def start_master(self) -> None:
        """``rosmaster --core`` on the ground; returns once it answers there."""
        self._start("master", ["rosmaster", "--core", "-p", str(MASTER_PORT)])
        probe = [sys.executable, "-c", _WAIT_MASTER, self.radio.master_uri(MASTER_PORT)]
        result = subprocess.run(
            self.radio.command(GROUND, [*probe, str(MASTER_START_TIMEOUT)]),
            capture_output=True,
            text=True,
            timeout=MASTER_START_TIMEOUT + 10.0,
            check=False,
        )
        if result.returncode != 0:
            raise AssertionError(f"rosmaster did not start on the ground:\n{self.log_tails()}")

    def start_launched_executor(self, agent: str, *launch_args: str) -> None:
        """``agent``'s executor as a robot's owner starts it.

        As docs/integrator-guide.md, "Robots on other machines", tells it.

        Only ``ROS_MASTER_URI`` is set: ``env.sh`` must find the robot's own address.
        """
        env = self.radio.environment(agent, self.env, MASTER_PORT)
        for name in ("ROS_IP", "ROS_HOSTNAME", "ROS_NAMESPACE"):
            env.pop(name, None)
        launch = [
            "roslaunch",
            "rosmc",
            "executor.launch",
            f"robot:={agent}",
            f"state_file:={self.state_file(agent)}",
            *launch_args,
        ]
        script = f"source {shlex.quote(str(REPO_ROOT / 'env.sh'))} && exec {shlex.join(launch)}"
        RosmcSystem._start(self, agent, self.radio.command(agent, ["bash", "-c", script]), env)

    def operator(self) -> RemoteOperator:
        """An operator on the ground (closed with the system)."""
        argv = [sys.executable, "-m", "tests.integration.remote_operator"]
        env = self.radio.environment(GROUND, self.env, MASTER_PORT)
        remote = RemoteOperator(
            self.radio.command(GROUND, argv),
            env,
            self.log(f"operator{len(self.operators)}"),
        )
        self.operators.append(remote)
        return remote

    def close(self) -> None:
        """Operators, then robots and emulator, then the server, then the master."""
        for remote in self.operators:
            remote.close()
        master = self.processes.pop("master", None)
        try:
            super().close()
        finally:
            if master is not None:
                self.processes["master"] = master
                self.stop("master")
