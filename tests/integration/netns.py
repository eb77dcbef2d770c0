"""A private network of Linux network namespaces: a ground station and robots on a "radio".

:class:`RadioLab` makes one namespace for the ground and one per robot. The ground holds a
bridge (the radio's shared medium); each robot reaches it through a veth pair whose ground
end is a bridge port (the robot's radio). Robots reach each other across the bridge too, as
robots on one radio network do. Every interface is made inside a namespace, so the host's
own interfaces, routes and addresses are never touched and no traffic leaves the lab: no
namespace has a route to anything but the lab's subnet.

The lab can shape every radio to a rate with ``tc tbf`` (both directions; the kernel here has
no ``netem``, so latency and loss come from the project's link emulator instead) and cut a
radio with ``ip link set down`` (its ground end: the robot's interface loses carrier, as a
radio does out of range).

Names start with :data:`PREFIX` and this process's PID, so parallel runs never collide and
:func:`sweep` can remove what a killed run left behind. :meth:`RadioLab.close` kills every
process inside the lab's namespaces and deletes them (their veths go with them), also when
the code using the lab failed.

Needs root (or ``CAP_NET_ADMIN`` and ``CAP_SYS_ADMIN``); :func:`unavailable` says why not.
Used by ``tests/integration/test_multihost.py`` and ``bench/bench_multihost.py``. Not a test
module: pytest collects nothing here.
"""

from __future__ import annotations

import contextlib
import itertools
import os
import re
import shutil
import signal
import subprocess
import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

PREFIX = "rmh"
GROUND = "ground"
BRIDGE = "radio"
ROBOT_RADIO = "radio0"  # the robot's interface, inside its namespace
_NAME = re.compile(rf"^{PREFIX}(\d+)x\d+-")
_COUNTER = itertools.count()
IP_TIMEOUT = 10.0


class LabError(RuntimeError):
    """An ``ip`` or ``tc`` command of the lab failed."""


def run_ip(*argv: str, check: bool = True) -> subprocess.CompletedProcess[str]:
    """Run ``ip``/``tc`` (``argv[0]``) with a timeout; raise :class:`LabError` if it fails."""
    result = subprocess.run(
        list(argv),
        capture_output=True,
        text=True,
        timeout=IP_TIMEOUT,
        check=False,
        stdin=subprocess.DEVNULL,
    )
    if check and result.returncode != 0:
        raise LabError(f"{' '.join(argv)}: {result.stderr.strip() or result.returncode}")
    return result


def unavailable() -> str:
    """Why this process cannot build a lab ("" if it can): not root, or namespaces refused."""
    if os.geteuid() != 0:
        return "network namespaces need root (ip netns add); run the test as root"
    for tool in ("ip", "tc"):
        if shutil.which(tool) is None:
            return f"'{tool}' (iproute2) is not installed"
    probe = f"{PREFIX}{os.getpid()}x{next(_COUNTER)}-probe"
    result = run_ip("ip", "netns", "add", probe, check=False)
    if result.returncode != 0:
        return f"'ip netns add' is refused here: {result.stderr.strip()}"
    delete_namespace(probe)
    return ""


def namespace_pids(namespace: str) -> list[int]:
    """The processes running in ``namespace``."""
    result = run_ip("ip", "netns", "pids", namespace, check=False)
    return [int(pid) for pid in result.stdout.split()]


def delete_namespace(namespace: str) -> None:
    """Kill every process in ``namespace``, then delete it (its interfaces go with it)."""
    for _ in range(50):
        pids = namespace_pids(namespace)
        if not pids:
            break
        for pid in pids:
            with contextlib.suppress(ProcessLookupError):
                os.kill(pid, signal.SIGKILL)
        time.sleep(0.05)
    run_ip("ip", "netns", "del", namespace, check=False)


def lab_namespaces() -> dict[str, int]:
    """Every namespace named like a lab's, with the PID of the process that made it."""
    result = run_ip("ip", "netns", "list", check=False)
    found = {}
    for line in result.stdout.splitlines():
        name = line.split()[0] if line.split() else ""
        match = _NAME.match(name)
        if match:
            found[name] = int(match.group(1))
    return found


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def sweep(own: bool = False) -> list[str]:
    """Delete labs whose maker is dead (and, with ``own``, this process's); their names."""
    removed = []
    for name, pid in lab_namespaces().items():
        if (own and pid == os.getpid()) or not _alive(pid):
            delete_namespace(name)
            removed.append(name)
    return removed


@dataclass(frozen=True)
class Host:
    """One machine of the lab: a namespace with one address on the radio subnet.

    Attributes:
        name: ``ground`` or the robot's agent name.
        namespace: The network namespace it runs in.
        address: Its IPv4 address (what ``ROS_IP`` is set to for its processes).
        radio: Its radio's interface in the ground namespace (the bridge port); "" for
            the ground.
    """

    name: str
    namespace: str
    address: str
    radio: str = ""


@dataclass
class RadioLab:
    """A ground namespace and one namespace per robot on a bridged private subnet.

    Use it as a context manager: entering builds the network, leaving kills every process
    in it and deletes the namespaces.

    Args:
        robots: Agent names, one namespace each.
        subnet: The third octet of ``10.213.<subnet>.0/24`` (any value: the lab's namespaces
            are private, so parallel labs with the same subnet never meet).
    """

    robots: Sequence[str]
    subnet: int = 0
    hosts: dict[str, Host] = field(default_factory=dict)

    def __post_init__(self) -> None:
        tag = f"{PREFIX}{os.getpid()}x{next(_COUNTER)}-"
        base = f"10.213.{self.subnet % 256}"
        self.hosts[GROUND] = Host(GROUND, tag + "g", f"{base}.1")
        for index, robot in enumerate(self.robots):
            self.hosts[robot] = Host(robot, f"{tag}{index}", f"{base}.{11 + index}", f"r{index}")

    @property
    def ground(self) -> Host:
        """The ground station's host."""
        return self.hosts[GROUND]

    def __enter__(self) -> RadioLab:
        try:
            self._build()
        except BaseException:
            self.close()
            raise
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def _in(self, host: Host, *argv: str) -> None:
        run_ip(argv[0], "-n", host.namespace, *argv[1:])

    def _build(self) -> None:
        ground = self.ground
        for host in self.hosts.values():
            run_ip("ip", "netns", "add", host.namespace)
            self._in(host, "ip", "link", "set", "lo", "up")
        self._in(ground, "ip", "link", "add", BRIDGE, "type", "bridge")
        self._in(ground, "ip", "addr", "add", f"{ground.address}/24", "dev", BRIDGE)
        self._in(ground, "ip", "link", "set", BRIDGE, "up")
        for host in self.hosts.values():
            if host is ground:
                continue
            self._in(
                ground,
                *("ip", "link", "add", host.radio, "type", "veth"),
                *("peer", "name", ROBOT_RADIO, "netns", host.namespace),
            )
            self._in(ground, "ip", "link", "set", host.radio, "master", BRIDGE, "up")
            self._in(host, "ip", "addr", "add", f"{host.address}/24", "dev", ROBOT_RADIO)
            self._in(host, "ip", "link", "set", ROBOT_RADIO, "up")

    def close(self) -> None:
        """Kill every process in the lab and delete its namespaces (never raises)."""
        for host in self.hosts.values():
            with contextlib.suppress(LabError, OSError, subprocess.SubprocessError):
                delete_namespace(host.namespace)

    # -- the radio ---------------------------------------------------------------------
    def _radios(self, robots: Sequence[str] | None) -> list[Host]:
        names = self.robots if robots is None else robots
        return [self.hosts[name] for name in names]

    def shape(
        self,
        rate: str,
        robots: Sequence[str] | None = None,
        burst: int = 4000,
        latency_ms: int = 200,
    ) -> None:
        """Limit the robots' radios to ``rate`` (tc syntax, e.g. ``256kbit``) both ways.

        ``burst`` (bytes) is how much may go at line speed after a quiet spell; a packet
        that would queue longer than ``latency_ms`` is dropped, as a radio's queue does.
        """
        tbf = ("root", "tbf", "rate", rate, "burst", str(burst), "latency", f"{latency_ms}ms")
        for host in self._radios(robots):
            self._in(self.ground, "tc", "qdisc", "replace", "dev", host.radio, *tbf)
            self._in(host, "tc", "qdisc", "replace", "dev", ROBOT_RADIO, *tbf)

    def unshape(self, robots: Sequence[str] | None = None) -> None:
        """Take the rate limit off the robots' radios."""
        for host in self._radios(robots):
            run_ip("tc", "-n", self.ground.namespace, "qdisc", "del", "dev", host.radio, "root")
            run_ip("tc", "-n", host.namespace, "qdisc", "del", "dev", ROBOT_RADIO, "root")

    def cut(self, robots: Sequence[str] | None = None) -> None:
        """Take the robots' radios down (their ground ends: the robots lose carrier)."""
        for host in self._radios(robots):
            self._in(self.ground, "ip", "link", "set", host.radio, "down")

    def restore(self, robots: Sequence[str] | None = None) -> None:
        """Bring the robots' radios back up."""
        for host in self._radios(robots):
            self._in(self.ground, "ip", "link", "set", host.radio, "up")

    def qdisc(self, robot: str) -> str:
        """``tc -s qdisc show`` of a robot's radio, both ends: the limit and what went through."""
        host = self.hosts[robot]
        show = ("tc", "-s", "qdisc", "show", "dev")
        ground_end = run_ip(show[0], "-n", self.ground.namespace, *show[1:], host.radio)
        robot_end = run_ip(show[0], "-n", host.namespace, *show[1:], ROBOT_RADIO)
        return ground_end.stdout + robot_end.stdout

    def sent_bytes(self, robot: str) -> tuple[int, int]:
        """Bytes a robot's radio has sent since it was shaped: (to the robot, from the robot)."""
        counts = [int(n) for n in re.findall(r"Sent (\d+) bytes", self.qdisc(robot))]
        if len(counts) != 2:
            raise LabError(f"{robot}'s radio is not shaped: {self.qdisc(robot)}")
        return counts[0], counts[1]

    # -- processes ------------------------------------------------------------------------
    def master_uri(self, port: int = 11311) -> str:
        """The URI of a master that runs on the ground at ``port``."""
        return f"http://{self.ground.address}:{port}/"

    def command(self, host: str, argv: Sequence[str]) -> list[str]:
        """``argv`` run inside ``host``'s namespace (``ip netns exec`` keeps the environment)."""
        return ["ip", "netns", "exec", self.hosts[host].namespace, *argv]

    def environment(self, host: str, base: Mapping[str, str], port: int = 11311) -> dict[str, str]:
        """``base`` for a ROS process on ``host``: its own ``ROS_IP``, the ground's master."""
        env = dict(base)
        env.pop("ROS_HOSTNAME", None)  # it would win over ROS_IP
        env.update(ROS_IP=self.hosts[host].address, ROS_MASTER_URI=self.master_uri(port))
        return env
