"""The review tools on a damaged recording: one line on stderr says what they skipped
(byte ranges and revisions), and they still do their job on the rest.

The recording is test_history's (the demo mission and a second act, journaled as the
server journals them); one event's chunk in the middle is damaged. No ROS master.
"""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

wire = pytest.importorskip("rosmc.msg", reason="rosmc messages are not built (source build/devel)")

import rosbag  # noqa: E402

from rosmc_server.cli import main as rosmc  # noqa: E402
from rosmc_server.interface import EVENTS_TOPIC  # noqa: E402
from rosmc_server.recording._mcap import scan as _scan  # noqa: E402
from rosmc_server.recording.history import MissionHistory  # noqa: E402
from tests.ros import test_history  # noqa: E402
from tests.ros.test_history import Recording  # noqa: E402

recording = test_history.recording  # the fixture, shared with this module
DAMAGED = 40  # the revision whose event is damaged


def event_span(path: Path, revision: int) -> tuple[int, int]:
    """The bytes of the chunk that holds the event of ``revision``."""
    scan = _scan.scan(path)
    events = next(c.id for c in scan.channels.values() if c.topic == EVENTS_TOPIC)
    for message, span in zip(scan.messages, scan.spans, strict=True):
        if message.channel_id == events and int.from_bytes(message.data[:8], "little") == revision:
            return span
    raise AssertionError(f"no event of revision {revision}")


@pytest.fixture
def damaged(recording: Recording, tmp_path: Path) -> tuple[Path, tuple[int, int]]:
    path = tmp_path / "mission.mcap"
    shutil.copy(recording.path, path)
    start, end = event_span(path, DAMAGED)
    data = bytearray(path.read_bytes())
    data[(start + end) // 2] ^= 0x20
    path.write_bytes(bytes(data))
    return path, (start, end)


def warnings(err: str) -> list[str]:
    return [line for line in err.splitlines() if "damaged" in line]


def test_at_timeline_info_and_tobag_say_what_they_skipped_in_one_line(
    recording: Recording,
    damaged: tuple[Path, tuple[int, int]],
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
) -> None:
    path, (start, end) = damaged
    history = MissionHistory.from_journal(path)
    [damage] = history.damage
    assert damage.start == start and damage.end > end  # the chunk and its message index
    end = damage.end
    [gap] = history.gaps
    resumed = gap.resumed_at
    assert gap.revisions.first == DAMAGED and resumed is not None
    line = (
        f"rosmc: warning: journal {path}: skipped damaged bytes {start}..{end - 1} of "
        f"mission.mcap (a damaged chunk record (its CRC does not match its content)); "
        f"{resumed - DAMAGED} revisions r{DAMAGED}..r{resumed - 1} cannot be rebuilt; the "
        f"mission continues from the snapshot of r{resumed}"
    )
    for revision in (DAMAGED - 1, resumed, max(recording.live)):  # the rest is all there
        assert history.at_revision(revision).content() == recording.live[revision]

    assert rosmc(["at", str(path), f"r{DAMAGED - 1}"]) == 0
    out, err = capsys.readouterr()
    assert f"at r{DAMAGED - 1} (revision {DAMAGED - 1})" in out
    assert warnings(err) == [line]
    assert rosmc(["at", str(path), f"r{DAMAGED}"]) == 1  # named, not shown
    capsys.readouterr()

    assert rosmc(["timeline", str(path), "-o", str(tmp_path / "t.svg")]) == 0
    assert warnings(capsys.readouterr().err) == [line]
    assert (tmp_path / "t.svg").stat().st_size > 0

    assert rosmc(["info", str(path)]) == 0
    out, err = capsys.readouterr()
    assert warnings(err) == [line]
    assert f"revisions 0..{max(recording.live)}" in out

    bag = tmp_path / "m.bag"
    assert rosmc(["tobag", str(path), str(bag)]) == 0
    out, err = capsys.readouterr()
    assert warnings(err) == [
        f"rosmc: warning: journal {path}: skipped damaged bytes {start}..{end - 1} of "
        f"mission.mcap (a damaged chunk record (its CRC does not match its content)); "
        f"revision r{DAMAGED} has no event"
    ]
    with rosbag.Bag(str(bag)) as reader:
        bagged = [m.revision for _, m, _ in reader.read_messages(topics=[EVENTS_TOPIC])]
    assert bagged == [r for r in sorted(recording.live) if r not in (0, DAMAGED)]
