"""The committed sample recording (bags/samples/demo.mcap): current, complete, exact, exportable.

The sample is the demo mission as the real mission server journaled it (simulated team,
scripted operator; ``tools/record_sample.py``), with a full snapshot of the server's own
mission every 20 events. The history rebuilt from it must equal every one of those
snapshots; the review commands read it; ``rosmc tobag`` turns it into a bag that
``rosbag`` and ``rosbags`` read message for message. No ROS master.
"""

from __future__ import annotations

import json
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest
from mcap.reader import make_reader

from rosmc_server.cli import main as rosmc
from rosmc_server.core import SkillStatus
from rosmc_server.interface import EVENTS_TOPIC, MISSION_TOPIC
from rosmc_server.recording import JOURNAL_TOPICS, JournalResult, read_journal
from rosmc_server.recording._mcap.codec import schema_of
from rosmc_server.recording.errors import JournalError
from rosmc_server.recording.history import MissionHistory
from tests.ros.recording_checks import (
    REGENERATE,
    SAMPLE,
    assert_bag_holds_the_journal,
    assert_history_is,
    assert_rosbags_reads_the_bag,
)


@pytest.fixture(scope="module")
def sample() -> JournalResult:
    return read_journal(SAMPLE)


@pytest.fixture(scope="module")
def history(sample: JournalResult) -> MissionHistory:
    return MissionHistory(sample)


def stale_definitions(path: Path) -> list[str]:
    """The types whose definition in ``path`` differs from the built message (or is unknown)."""
    with path.open("rb") as stream:
        summary = make_reader(stream).get_summary()
    assert summary is not None, f"{path} has no summary"
    stale = []
    for schema in summary.schemas.values():
        try:
            built = schema_of(schema.name)
        except JournalError:
            built = b""
        if built != schema.data:
            stale.append(schema.name)
    return sorted(stale)


def test_the_sample_embeds_the_current_message_definitions() -> None:
    stale = stale_definitions(SAMPLE)
    assert not stale, (
        f"{SAMPLE.relative_to(SAMPLE.parents[2])} was recorded with other definitions of "
        f"{', '.join(stale)} than the messages built now: {REGENERATE}"
    )


def test_the_check_notices_a_changed_definition(tmp_path: Path) -> None:
    # The sample with one definition edited as a message change would: the check names it.
    data = SAMPLE.read_bytes()
    before = schema_of("rosmc/ScienceState")
    edited = before.replace(b"uint32 stones_delivered", b"uint32 stones_dropped  ")
    assert len(edited) == len(before) and edited != before
    copy = tmp_path / "old.mcap"
    copy.write_bytes(data.replace(before, edited))
    assert stale_definitions(copy) == ["rosmc/ScienceState"]


def test_the_sample_is_small_closed_and_holds_every_channel(sample: JournalResult) -> None:
    assert SAMPLE.stat().st_size < 1_000_000
    assert sample.clean, sample.warnings
    counts = {topic: len(sample.messages(topic)) for topic in JOURNAL_TOPICS}
    assert all(counts.values()), f"a channel is empty: {counts}"
    assert counts[MISSION_TOPIC] >= 3, "the server's own snapshots to check against"


def test_every_revision_rebuilds_and_equals_the_servers_snapshots(
    sample: JournalResult, history: MissionHistory
) -> None:
    events = [int(m.revision) for m in sample.messages(EVENTS_TOPIC)]
    first = int(sample.messages(MISSION_TOPIC)[0].revision)  # 1 since fresh missions start there
    assert events == list(range(first + 1, first + 1 + len(events)))
    assert [r.revision for r in history.revisions] == [first, *events]
    assert history.problems == ()
    truth = {int(m.revision): m for m in sample.messages(MISSION_TOPIC)}
    assert len(truth) >= 3 and max(truth) > len(events) // 2
    assert_history_is(history, truth)


def test_the_replayed_demo_ends_with_every_skill_done(history: MissionHistory) -> None:
    final = history.at_revision(history.revisions[-1].revision)
    skills = [skill for task in final.content().tasks.values() for skill in task]
    assert len(final.content().tasks) == 3 and len(skills) >= 10
    assert {skill.status for skill in skills} == {SkillStatus.SUCCESS}


def test_the_review_commands_read_the_sample(
    history: MissionHistory, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    first, last = history.revisions[0].revision, history.revisions[-1].revision
    assert rosmc(["--json", "info", str(SAMPLE)]) == 0
    info = json.loads(capsys.readouterr().out)
    assert info["revisions"] == [first, last] and info["problems"] == []
    assert {robot["agent"]: robot["failed"] for robot in info["robots"]} == {
        "drone": 0,
        "science_rover": 0,
        "manipulator_rover": 0,
    }
    assert info["final_score"] > 0
    middle = history.revisions[len(history.revisions) // 2]
    assert rosmc(["at", str(SAMPLE), f"{history.seconds(middle.log_time):.9f}", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["revision"] == middle.revision
    assert rosmc(["--json", "diff", str(SAMPLE), f"r{first}", f"r{last}"]) == 0
    assert json.loads(capsys.readouterr().out)["to"]["revision"] == last
    assert rosmc(["timeline", str(SAMPLE), "-o", str(tmp_path / "t.svg")]) == 0
    assert "3 robots" in capsys.readouterr().out
    ET.parse(tmp_path / "t.svg")


def test_tobag_holds_every_message_for_rosbag_and_rosbags(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bag = tmp_path / "demo.bag"
    assert rosmc(["tobag", str(SAMPLE), str(bag)]) == 0
    assert "wrote" in capsys.readouterr().out
    assert_bag_holds_the_journal(SAMPLE, bag)
    assert_rosbags_reads_the_bag(bag, SAMPLE)
