"""The journal's disk fills up: changes are refused with a sentence, reads go on, changes
resume by themselves once space returns, and a journal that fails for good ends the server
with a non-zero exit status (so a supervisor restarts it).

A real server journals onto a real 4 MiB tmpfs that the test fills with a plain file.
"""

from __future__ import annotations

import contextlib
import errno
import os
import re
import resource
import subprocess
import sys
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest
import rosmc.msg as wire
import rospy
from rosmc.msg import ErrorCode

pytest.register_assert_rewrite("tests.integration.server_fixtures")

from rosmc_server.ros.client.follow import MissionFollower  # noqa: E402
from tests.conftest import wait_until  # noqa: E402
from tests.integration.server_fixtures import REPO, Client, ServerProcess  # noqa: E402
from tests.integration.test_server_crash import large_document  # noqa: E402

pytest_plugins = ["tests.integration.server_fixtures"]

FULL = re.compile(r"^the journal's disk is full: \d+ bytes free$")


@pytest.fixture
def small_disk(tmp_path: Path) -> Iterator[Path]:
    """A 4 MiB tmpfs, unmounted after the test."""
    disk = tmp_path / "disk"
    disk.mkdir()
    subprocess.run(["mount", "-t", "tmpfs", "-o", "size=4m", "tmpfs", str(disk)], check=True)
    try:
        yield disk
    finally:
        subprocess.run(["umount", "-l", str(disk)], check=False)


def fill(path: Path) -> None:
    """Write ``path`` until the disk it is on has no byte left."""
    block = os.urandom(64 * 1024)
    with path.open("wb", buffering=0) as file:
        while True:
            try:
                file.write(block)
            except OSError as err:
                assert err.errno == errno.ENOSPC, err
                break
        with contextlib.suppress(OSError):
            while file.write(b"x"):
                pass


def add_marker(client: Client, name: str, x: float) -> object:
    """Ask for one task marker against the current revision."""
    return client.call(
        "add_task_marker",
        base_revision=client.revision(),
        marker=wire.TaskMarker(name=name, type=1, pose=wire.Pose6D(x=x)),
    )


def marker_names(client: Client) -> list[str]:
    """The task markers of the server's mission."""
    return [marker.name for marker in client.mission().markers]


def rosmc_status(server: ServerProcess) -> str:
    """``rosmc status --no-states`` against the test's master."""
    return subprocess.run(
        [sys.executable, str(REPO / "scripts" / "rosmc"), "status", "--no-states"],
        env=server.env,
        capture_output=True,
        text=True,
        timeout=60,
        check=True,
    ).stdout


def test_a_full_disk_refuses_changes_keeps_reads_and_resumes_when_space_returns(
    start_server: Callable[..., ServerProcess], small_disk: Path
) -> None:
    journal = small_disk / "mission.mcap"
    server = start_server("diskfull", journal=journal)
    filler = small_disk / "filler"
    alerts: list[str] = []  # what the GUIs are told, as they follow the server
    follower = MissionFollower(check_period=0.2, on_journal_alert=alerts.append)
    follower.start()
    with contextlib.ExitStack() as cleanup, Client() as client:
        cleanup.callback(follower.close)
        assert add_marker(client, "Before", 1.0).error_code == ErrorCode.NONE
        before = client.revision()
        fill(filler)
        refused = add_marker(client, "Refused", 2.0)
        assert refused.error_code == ErrorCode.UNAVAILABLE
        assert FULL.match(refused.error), refused.error
        assert refused.revision == before
        # Reads go on; nothing of the refused change is there; the server runs on.
        assert client.revision() == before and marker_names(client) == ["Before"]
        assert server.alive
        status = rosmc_status(server).splitlines()[0]
        assert status.startswith("the journal's disk is full: "), status
        assert status.endswith(f"in {small_disk}: changes are refused until space returns")
        wait_until(lambda: alerts and FULL.match(alerts[-1].split(" in ")[0]), 20.0, "an alert")
        filler.unlink()  # space returns: the next change goes through, nobody restarts anything
        after = add_marker(client, "After", 3.0)
        assert after.error_code == ErrorCode.NONE, after.error
        assert after.revision == before + 1
        assert "disk is full" not in rosmc_status(server)
        wait_until(lambda: alerts[-1] == "", 20.0, "the alert to clear")
    server.kill9()  # every acknowledged change is in the journal, the refused one is not
    start_server("diskfull", journal=journal, resume=True)
    with Client() as client:
        assert marker_names(client) == ["Before", "After"]
        assert client.revision() == before + 1


def test_a_server_whose_journal_fails_exits_with_a_non_zero_status(
    start_server: Callable[..., ServerProcess], tmp_path: Path
) -> None:
    journal = tmp_path / "limited.mcap"
    server = start_server("limited", journal=journal)
    with Client() as client:
        assert add_marker(client, "Kept", 1.0).error_code == ErrorCode.NONE
        kept = client.revision()
        # The server may not grow any file past its size now: the next write fails (EFBIG).
        size = journal.stat().st_size
        resource.prlimit(server.pid, resource.RLIMIT_FSIZE, (size + 16, size + 16))
        failed = add_marker(client, "Lost", 2.0)
        assert failed.error_code != ErrorCode.NONE  # never acknowledged
    assert server.process is not None
    wait_until(lambda: server.process.poll() is not None, 30.0, "the server exits")
    assert server.process.returncode == 1
    assert "cannot write the journal" in server.log()
    start_server("limited", journal=journal, resume=True)
    with Client() as client:
        assert marker_names(client) == ["Kept"] and client.revision() == kept


def test_a_load_the_disk_cannot_hold_is_never_shown_and_costs_nothing_at_later_restarts(
    start_server: Callable[..., ServerProcess], small_disk: Path
) -> None:
    """The load passes the reserve check, then its snapshot meets a full disk mid-write: it
    is refused, nobody sees it, and two restarts later every acknowledged change is there."""
    journal = small_disk / "mission.mcap"
    reserve = 8192  # far below the big load's snapshot (compressed: tens of kB)
    server = start_server("loadfull", journal=journal, journal_reserve=reserve)
    document = large_document("big", 15_000)
    filler = small_disk / "filler"
    with Client() as client:
        assert add_marker(client, "Before", 1.0).error_code == ErrorCode.NONE
        before = client.revision()
        fill(filler)
        with filler.open("r+b") as file:  # room for the reserve, not for the big snapshot
            file.truncate(filler.stat().st_size - reserve - 4096)
        failed = client.call("load_mission", base_revision=before, document=document)
        assert failed.error_code != ErrorCode.NONE  # never acknowledged
        with contextlib.suppress(rospy.ServiceException):  # or it is already gone
            shown = client.call("get_mission").mission
            assert shown.revision == before, "a change that is not durable was shown"
    assert server.process is not None
    wait_until(lambda: server.process.poll() is not None, 30.0, "the server exits")
    filler.unlink()
    server = start_server("loadfull", journal=journal, resume=True)
    with Client() as client:
        assert client.revision() == before and marker_names(client) == ["Before"]
        for name in ("After1", "After2"):
            assert add_marker(client, name, 2.0).error_code == ErrorCode.NONE
        after = client.revision()
    server.kill9()
    start_server("loadfull", journal=journal, resume=True)
    with Client() as client:
        assert marker_names(client) == ["Before", "After1", "After2"]
        assert client.revision() == after
        assert client.call("get_mission").journal_alert == ""
