"""The MCAP mission journal: every accepted change, durably, for crash recovery and replay.

The mission server appends each accepted change (``rosmc/MissionEvent``) and
periodic full snapshots (``rosmc/Mission``) to an MCAP file in ROS 1 encoding
with the ``rosmc`` message definitions embedded, so Foxglove and the ``mcap``
tools read it; a long journal goes on in part files beside the first (see
:mod:`._mcap.files`), which every reader follows. After a crash,
:meth:`JournalWriter.resume` recovers every intact record (skipping damaged
bytes, see :mod:`._mcap.scan`) and continues the journal; :func:`latest_state` gives
the snapshot and events to rebuild the mission from, and the revisions lost.

Typical use::

    writer = JournalWriter.create(default_journal_path("bags"), mission_msg, now_ns)
    writer.append_event(event_msg, now_ns)  # before replying to the operator
    if writer.snapshot_due:
        writer.append_snapshot(mission_msg, now_ns)
    writer.close()

    writer = JournalWriter.resume(path)  # after a crash
    state = latest_state(writer.recovered)
"""

from rosmc_server.recording._mcap.files import default_journal_path
from rosmc_server.recording.channels import JOURNAL_TOPICS
from rosmc_server.recording.errors import JournalError
from rosmc_server.recording.journal_options import JournalOptions
from rosmc_server.recording.reader import (
    JournalRecord,
    JournalResult,
    LatestState,
    latest_state,
    read_journal,
)
from rosmc_server.recording.writer import JournalWriter

__all__ = [
    "JOURNAL_TOPICS",
    "JournalError",
    "JournalOptions",
    "JournalRecord",
    "JournalResult",
    "JournalWriter",
    "LatestState",
    "default_journal_path",
    "latest_state",
    "read_journal",
]
