"""A journal that lost its end (cut or zeroed from its last snapshot on) resumes loudly.

The journal's revision mark (``<journal>.revisions``, kept apart from its body) knows the
last acknowledged revision, so the resume sees that revisions are missing: one ERROR line,
a ``rosmc status`` alert, a new epoch, and revision numbers that never repeat; a client whose
view held the lost changes is refused as stale.
"""

from __future__ import annotations

import json
import random
import threading
from collections.abc import Callable
from pathlib import Path

import pytest
import rosmc.msg as wire

pytest.register_assert_rewrite("tests.integration.server_fixtures")

from rosmc_server import interface  # noqa: E402
from rosmc_server.recording._mcap import scan as _scan  # noqa: E402
from rosmc_server.recording.high_water import read_mark  # noqa: E402
from tests.conftest import wait_until  # noqa: E402
from tests.integration.server_fixtures import Client, Recorder, ServerProcess  # noqa: E402
from tests.integration.test_server_crash import Expected, Session, _rosmc, operate  # noqa: E402

pytest_plugins = ["tests.integration.server_fixtures"]


def snapshot_records(journal: Path) -> list[tuple[int, int]]:
    """(offset, revision) of every snapshot record of the journal."""
    scan = _scan.scan(journal)
    channel = next(c.id for c in scan.channels.values() if c.topic == interface.MISSION_TOPIC)
    return [
        (span[0], int.from_bytes(message.data[:8], "little"))
        for message, span in zip(scan.messages, scan.spans, strict=True)
        if message.channel_id == channel
    ]


def snapshots(journal: Path) -> int:
    """How many snapshots the journal holds."""
    return len(snapshot_records(journal))


@pytest.mark.parametrize("damage", ["cut", "zeroed"])
def test_a_journal_that_lost_its_end_resumes_loudly_and_never_reuses_a_revision(
    start_server: Callable[..., ServerProcess], tmp_path: Path, damage: str
) -> None:
    journal = tmp_path / "end.mcap"
    server = start_server("end", journal=journal, snapshot_every=20)
    rng = random.Random(5)
    with Client() as client:
        expected = Expected(client.mission())
        session = Session()
        operate(client, expected, rng, 60, -1, threading.Event(), session)
        wait_until(lambda: snapshots(journal) >= 2, 30.0, "a snapshot is journaled")
        snapshot_at = expected.revision
        operate(client, expected, rng, 15, -1, threading.Event(), session)  # none is due
        assert session.error is None and session.in_flight is None, session
    last = expected.revision
    assert last > snapshot_at
    server.kill9()
    old_epoch = read_mark(journal)
    assert old_epoch is not None and old_epoch.revision == last
    offset, snapshot_revision = snapshot_records(journal)[-1]
    assert snapshot_revision <= snapshot_at
    size = journal.stat().st_size
    with journal.open("r+b") as handle:
        if damage == "cut":
            handle.truncate(offset)
        else:
            handle.seek(offset)
            handle.write(bytes(size - offset))

    server = start_server("end", journal=journal, resume=True)
    errors = [line for line in server.log().splitlines() if "[ERROR]" in line]
    assert len(errors) == 1, errors
    assert f"r{snapshot_revision + 1}..r{last} lost from its end" in errors[0], errors[0]
    mark = read_mark(journal)
    assert mark is not None and mark.epoch != old_epoch.epoch  # the history changed
    status = _rosmc(server, "status", "--no-states").splitlines()[0]
    assert status.startswith("journal: ") and f"..r{last}" in status, status
    assert json.loads(_rosmc(server, "--json", "status", "--no-states"))["journal_alert"] == status
    with Client() as client:
        resumed = client.revision()
        assert resumed > last  # above every revision handed out before, lost ones included
        assert resumed > old_epoch.high_water
        marker = wire.TaskMarker(name="After", type=1, pose=wire.Pose6D(x=1.0))
        stale = client.call("add_task_marker", base_revision=last, marker=marker)
        assert stale.error_code == wire.ErrorCode.CONFLICT, stale.error  # held lost changes
        events = Recorder(interface.EVENTS_TOPIC, wire.MissionEvent)
        try:
            fresh = client.call("add_task_marker", base_revision=resumed, marker=marker)
            assert fresh.error_code == wire.ErrorCode.NONE and fresh.revision == resumed + 1
            # Answers and events name the new history, so a mirror of the old one refetches.
            event = events.wait_for(lambda ms: any(m.revision == resumed + 1 for m in ms))[-1]
        finally:
            events.close()
        assert event.epoch == mark.epoch == client.call("get_mission").epoch
