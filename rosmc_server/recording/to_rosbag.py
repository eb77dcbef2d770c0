"""Converting a mission journal (MCAP) to a rosbag1 file for ``rosbag play``.

Every recorded message keeps its topic, its bytes and its recorded definition (type,
md5sum and full text, as the journal embeds it); the mission snapshots, the site and the
score are marked latched, as the mission server and the simulator publish them, so a late
subscriber to a ``rosbag play`` gets the last one played. The bag's time is the mission
clock the stamps use (sim time under simulation, :mod:`.bag_clock`), not the journal's log
time, so ``rosbag play --clock`` publishes a ``/clock`` that the ``/tf`` stamps agree with.
"""

from __future__ import annotations

import logging
from collections import Counter
from dataclasses import dataclass
from pathlib import Path

import genpy
import rosbag

from rosmc_server.interface import EVENTS_TOPIC, SERVER_NODE
from rosmc_server.recording.bag_clock import MissionClock
from rosmc_server.recording.channels import LATCHED_TOPICS
from rosmc_server.recording.damage import skipped_line
from rosmc_server.recording.errors import JournalError
from rosmc_server.recording.reader import read_journal
from rosmc_server.recording.revisions import missing_revisions

_log = logging.getLogger(__name__)

CALLER_ID = SERVER_NODE
"""The publisher the bag names: the node that published these topics live."""


@dataclass(frozen=True)
class BagSummary:
    """What a conversion wrote.

    Attributes:
        path: The bag file.
        counts: Messages per topic.
        warnings: What reading the journal found wrong (a cut-off tail, ...).
        skipped: One line on the damaged bytes skipped and the revisions whose event the
            bag therefore lacks ("" if none).
        clock: Whose stamps the bag's time follows: ``/tf`` (and so sim time in a
            simulation), another topic, or ``log time`` for a recording without stamps.
    """

    path: Path
    counts: dict[str, int]
    warnings: tuple[str, ...]
    skipped: str = ""
    clock: str = ""

    @property
    def total(self) -> int:
        """Messages written."""
        return sum(self.counts.values())


def journal_to_rosbag(
    journal: str | Path, bag_path: str | Path, *, overwrite: bool = False
) -> BagSummary:
    """Write every intact record of ``journal`` into a new rosbag1 file at ``bag_path``.

    Raises:
        JournalError: The journal cannot be read, the bag exists (without ``overwrite``)
            or cannot be written.
    """
    bag_path = Path(bag_path)
    if bag_path.exists() and not overwrite:
        raise JournalError(f"{bag_path} exists already; remove it or choose another name")
    result = read_journal(journal)
    clock = MissionClock.of(result.records)
    counts: Counter[str] = Counter()
    try:
        with rosbag.Bag(str(bag_path), "w") as bag:
            for record in result.records:
                message = record.message
                header = {
                    "topic": record.topic,
                    "type": message._type,
                    "md5sum": message._md5sum,
                    "message_definition": message._full_text,
                    "callerid": CALLER_ID,
                    "latching": "1" if record.topic in LATCHED_TOPICS else "0",
                }
                when = clock.time_of(record)
                stamp = genpy.Time(when // 10**9, when % 10**9)
                bag.write(record.topic, message, stamp, connection_header=header)
                counts[record.topic] += 1
    except (OSError, ValueError, rosbag.ROSBagException, genpy.SerializationError) as err:
        bag_path.unlink(missing_ok=True)
        raise JournalError(f"cannot write the bag {bag_path}: {err}") from err
    _log.info("wrote %d messages of %s to %s", sum(counts.values()), result.path, bag_path)
    revisions = (int(r.message.revision) for r in result.records if r.topic == EVENTS_TOPIC)
    skipped = skipped_line(result.path, result.damage, missing=missing_revisions(revisions))
    return BagSummary(bag_path, dict(counts), result.warnings, skipped, clock.source)
