"""A damaged journal: every intact record is kept, what is lost is named, resume goes on.

Real journals from the real JournalWriter in tmp_path, one byte (or a length field)
flipped at the start, in the middle, inside a chunk and inside a snapshot, in both
layouts. No ROS master.

The chunked layout (the default) has a CRC per record: any damage is found. The bare
layout has none: damage to a record's head (opcode, length, channel) is found, damage
inside a message only if it no longer decodes, so its tests flip bytes of those kinds.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pytest
from mcap.reader import SeekingReader
from mcap.stream_reader import StreamReader

msg = pytest.importorskip("rosmc.msg", reason="rosmc messages are not built (source build/devel)")

from rosmc_server.interface import EVENTS_TOPIC, MISSION_TOPIC  # noqa: E402
from rosmc_server.recording import (  # noqa: E402
    JournalOptions,
    JournalWriter,
    latest_state,
    read_journal,
)
from rosmc_server.recording._mcap.records import (  # noqa: E402
    MAGIC,
    FormatError,
    iter_records,
    read_chunk,
)
from rosmc_server.recording.recovery import ResumeReport  # noqa: E402
from tests.ros.test_journal import event, mission  # noqa: E402

T0 = 1_700_000_000_000_000_000
EVENTS = 120
SNAPSHOT_EVERY = 25  # snapshots of revisions 25, 50, 75, 100 follow their event
HEAD = 9  # opcode and length of every record
# Inside an event's payload: the high byte of the length of its first string (agent);
# inside a snapshot's: of its first string (library). Either makes a message undecodable.
PAYLOAD = {"chunked": HEAD + 40 + HEAD + 22 + 20, "bare": HEAD + 22 + 20}
SNAPSHOT_PAYLOAD = HEAD + 22 + 19
LAYOUTS = ["chunked", "bare"]


@dataclass(frozen=True)
class Row:
    """One record the writer appended: what, and the bytes of the file it took."""

    topic: str
    revision: int
    start: int
    end: int


def write(path: Path, layout: str, events: int = EVENTS) -> list[Row]:
    """A journal of ``events`` events with snapshots (compressed when chunked) and a robot
    report now and then; left unclosed, as a crash leaves it."""
    options = JournalOptions(
        chunked=layout == "chunked", snapshot_every=SNAPSHOT_EVERY, compress_from=1024
    )
    writer = JournalWriter.create(path, mission(0, agents=3, skills=40), T0, options)
    data = path.read_bytes()
    opening = next(o for o, op, _ in iter_records(data, len(MAGIC)) if op in (5, 6))
    rows = [Row(MISSION_TOPIC, 0, opening, writer.offset)]
    for rev in range(1, events + 1):
        start = writer.offset
        writer.append_event(event(rev), T0 + rev * 1000)
        rows.append(Row(EVENTS_TOPIC, rev, start, writer.offset))
        if writer.snapshot_due:
            start = writer.offset
            writer.append_snapshot(mission(rev, agents=3, skills=40), T0 + rev * 1000 + 1)
            rows.append(Row(MISSION_TOPIC, rev, start, writer.offset))
        if rev % 10 == 5:
            writer.append_report(msg.RobotReport(agent="drone", seq=rev), T0 + rev * 1000 + 2)
    writer.abandon()
    return rows


def flip(path: Path, offset: int, mask: int = 0x40) -> bytes:
    """Flip bits of one byte of ``path``; return the damaged content."""
    data = bytearray(path.read_bytes())
    data[offset] ^= mask
    path.write_bytes(bytes(data))
    return bytes(data)


def revisions(result: Any, topic: str = EVENTS_TOPIC) -> list[int]:
    return [int(r.message.revision) for r in result.records if r.topic == topic]


def event_row(rows: list[Row], revision: int) -> Row:
    return next(r for r in rows if r.topic == EVENTS_TOPIC and r.revision == revision)


def snapshot_row(rows: list[Row], revision: int) -> Row:
    return next(r for r in rows if r.topic == MISSION_TOPIC and r.revision == revision)


def mcap_read(path: Path) -> int:
    """How many messages the mcap package reads, indexed and sequentially (CRCs checked)."""
    with path.open("rb") as file:
        count = len(list(SeekingReader(file, validate_crcs=True).iter_messages()))
    with path.open("rb") as file:
        records = list(StreamReader(file, validate_crcs=True).records)
    assert records
    return count


# -- one flipped byte --------------------------------------------------------------------
@dataclass(frozen=True)
class Case:
    """Where a byte is flipped and what that costs."""

    name: str
    lost_event: int | None  # the event whose record the flip destroys
    lost_snapshot: int | None
    gap: str | None  # the revisions that cannot be rebuilt, as the reader names them
    resumed_at: int | None  # the snapshot after the gap


CASES = [
    Case("opening snapshot", None, 0, "r1..r24", 25),
    Case("first event", 1, None, "r1..r24", 25),
    Case("middle event", 60, None, "r60..r74", 75),
    Case("inside a snapshot", None, 50, None, None),
    Case("last event before a snapshot", 100, None, "r100..r100", None),
]


def target(case: Case, rows: list[Row], layout: str, path: Path) -> int:
    if case.lost_event is not None:
        return event_row(rows, case.lost_event).start + PAYLOAD[layout]
    assert case.lost_snapshot is not None
    row = snapshot_row(rows, case.lost_snapshot)
    if layout == "bare":
        return row.start + SNAPSHOT_PAYLOAD
    return damaging(path, row)


def damaging(path: Path, row: Row) -> int:
    """A byte in the middle of a compressed chunk whose flip changes what it holds.

    zstd leaves some bits unused: flipping one of those changes nothing, and the chunk
    (its CRC still matching) is rightly kept.
    """
    data = path.read_bytes()
    original, _ = read_chunk(data, row.start + HEAD)
    for offset in range((row.start + row.end) // 2, row.end):
        damaged = bytearray(data)
        damaged[offset] ^= 0x40
        try:
            if read_chunk(bytes(damaged), row.start + HEAD)[0].data != original.data:
                return offset
        except FormatError:
            return offset
    raise AssertionError("no byte of the chunk matters")


@pytest.mark.parametrize("layout", LAYOUTS)
@pytest.mark.parametrize("case", CASES, ids=lambda c: c.name.replace(" ", "-"))
def test_a_flipped_byte_costs_only_its_record(tmp_path: Path, layout: str, case: Case) -> None:
    path = tmp_path / "j.mcap"
    rows = write(path, layout)
    offset = target(case, rows, layout, path)
    flip(path, offset)
    result = read_journal(path)
    kept_events = [r.revision for r in rows[1:] if r.topic == EVENTS_TOPIC]
    kept_snapshots = [r.revision for r in rows if r.topic == MISSION_TOPIC]
    if case.lost_event is not None:
        kept_events.remove(case.lost_event)
    if case.lost_snapshot is not None:
        kept_snapshots.remove(case.lost_snapshot)
    assert revisions(result) == kept_events  # every intact record after the damage too
    assert revisions(result, MISSION_TOPIC) == kept_snapshots
    [damage] = result.damage
    assert damage.start <= offset < damage.end and not damage.kept
    state = latest_state(result)
    assert state.highest == EVENTS and state.next_revision == EVENTS + 1
    gaps = [(str(g.revisions), g.resumed_at) for g in state.gaps]
    if case.name == "last event before a snapshot":
        # The snapshot of r100 follows its event: only r100's own change is unseen.
        assert gaps == [] and state.revision == EVENTS
    else:
        assert gaps == ([(case.gap, case.resumed_at)] if case.gap else [])
        assert state.revision == EVENTS and state.lost is None


@pytest.mark.parametrize("layout", LAYOUTS)
def test_every_byte_of_a_record_flipped_loses_at_most_that_record(
    tmp_path: Path, layout: str
) -> None:
    """Chunked: every byte of the chunk and its index. Bare: the record's head and the
    message's own fields (channel, sequence, times); its payload has no checksum."""
    path = tmp_path / "j.mcap"
    rows = write(path, layout, events=30)
    clean = path.read_bytes()
    row = event_row(rows, 12)
    for offset in range(row.start, row.end if layout == "chunked" else row.start + HEAD + 22):
        path.write_bytes(clean)
        flip(path, offset, 0x10)
        result = read_journal(path)
        got = revisions(result)
        others = [r for r in range(1, 31) if r != 12]
        assert [r for r in got if r != 12] == others, offset
        # Damage is named only inside the record hit: a length made shorter can leave the
        # rest of the record to be skipped as a second damaged range (e.g. where an empty
        # array's zero bytes read as opcode 0), never an intact record.
        for damage in result.damage:
            assert row.start <= damage.start < damage.end <= row.end, (offset, damage)
        state = latest_state(result)
        assert state.next_revision == 31, offset
        if 12 not in got:  # the record itself was lost: named, as the revisions it cost
            assert result.damage, offset
            assert [str(g.revisions) for g in state.gaps] == ["r12..r24"], offset


@pytest.mark.parametrize("layout", LAYOUTS)
@pytest.mark.parametrize(("byte", "mask"), [(0, 0x01), (0, 0x02), (1, 0x01), (3, 0x80), (7, 0x80)])
def test_a_damaged_length_field_hides_no_record(
    tmp_path: Path, layout: str, byte: int, mask: int
) -> None:
    """Longer or shorter, near or past the end of the file: no other record is lost. A
    chunk is kept whole (its CRC vouches for it); so is a bare message made longer."""
    path = tmp_path / "j.mcap"
    rows = write(path, layout, events=30)
    row = event_row(rows, 12)
    where = row.start + 1 + byte
    longer = not bytearray(path.read_bytes())[where] & mask
    flip(path, where, mask)
    result = read_journal(path)
    got = revisions(result)
    assert [r for r in got if r != 12] == [r for r in range(1, 31) if r != 12]
    assert any(d.start <= where < d.end for d in result.damage)
    if layout == "chunked" or longer:
        assert got == list(range(1, 31))
        assert [d.kept for d in result.damage] == [True]
        assert latest_state(result).gaps == ()
    else:  # a bare message cut short by its length is lost, and named
        assert [str(g.revisions) for g in latest_state(result).gaps] == ["r12..r24"]


def test_a_damaged_opcode_of_a_chunk_keeps_the_chunk(tmp_path: Path) -> None:
    path = tmp_path / "j.mcap"
    rows = write(path, "chunked", events=30)
    flip(path, event_row(rows, 12).start, 0x80)  # 0x06 -> 0x86, a private opcode
    result = read_journal(path)
    assert revisions(result) == list(range(1, 31))
    assert [(d.kept, d.what) for d in result.damage] == [(True, "a damaged opcode or length field")]


def test_damage_in_the_last_events_loses_them_but_not_their_numbers(tmp_path: Path) -> None:
    path = tmp_path / "j.mcap"
    rows = write(path, "chunked")
    flip(path, event_row(rows, EVENTS - 3).start + PAYLOAD["chunked"])
    state = latest_state(read_journal(path))
    # r118..r120 are intact but cannot be applied without r117, and no snapshot follows.
    assert state.revision == EVENTS - 4
    assert state.lost is not None and str(state.lost.revisions) == f"r{EVENTS - 3}..r{EVENTS}"
    assert state.next_revision == EVENTS + 1


def test_a_damaged_declaration_is_rebuilt_from_the_journal_channels(tmp_path: Path) -> None:
    """The schemas and channels at the start of a journal have no checksum: a damaged one
    is skipped and the journal's fixed channel list stands in for it."""
    path = tmp_path / "j.mcap"
    write(path, "chunked", events=30)
    data = path.read_bytes()
    channel = data.index(EVENTS_TOPIC.encode())  # inside the events channel's declaration
    flip(path, channel + 3)
    result = read_journal(path)
    assert revisions(result) == list(range(1, 31))
    assert len(result.damage) == 1 and result.damage[0].start < channel < result.damage[0].end
    assert any("rebuilt from the journal's fixed channel list" in w for w in result.warnings)


@pytest.mark.parametrize("layout", LAYOUTS)
def test_a_flipped_byte_anywhere_in_the_declarations_loses_nothing(
    tmp_path: Path, layout: str
) -> None:
    """Every 37th byte of the 20 kB of schemas and channels after the header: a damaged
    definition text, type name, id, topic or length; every record is still read."""
    path = tmp_path / "j.mcap"
    rows = write(path, layout, events=30)
    clean = path.read_bytes()
    header_end = len(MAGIC) + HEAD + clean[len(MAGIC) + 1]
    for offset in range(header_end, rows[0].start, 37):
        path.write_bytes(clean)
        flip(path, offset, 0x10)
        result = read_journal(path)
        assert revisions(result) == list(range(1, 31)), offset
        assert latest_state(result).revision == 30, offset


# -- resume -------------------------------------------------------------------------------
@pytest.mark.parametrize("layout", LAYOUTS)
def test_resume_after_damage_goes_on_in_a_new_part(tmp_path: Path, layout: str) -> None:
    path = tmp_path / "j.mcap"
    rows = write(path, layout)
    damaged = flip(path, event_row(rows, 110).start + PAYLOAD[layout])
    writer = JournalWriter.resume(path)
    assert writer.damaged and writer.needs_snapshot
    assert writer.path == path and writer.part_path == tmp_path / "j.part002.mcap"
    assert writer.recovered is not None
    state = latest_state(writer.recovered)
    assert state.revision == 109 and state.next_revision == EVENTS + 1
    report = ResumeReport.of(path, writer.recovered.damage, state, writer.part_path)
    assert report.alert() == (
        f"journal: 11 revisions lost at resume (r110..r120: the mission resumed at r109, "
        f"next revision r121), see {path}"
    )
    line = report.log_line()
    assert f"skipped damaged bytes {writer.recovered.damage[0].start}.." in line
    assert "r110..r120" in line and line.endswith("goes on in j.part002.mcap")
    # What the server does next: a snapshot above every revision seen, then new changes.
    writer.append_snapshot(mission(EVENTS), T0 + 10**9)
    writer.append_event(event(EVENTS + 1), T0 + 10**9 + 1)
    writer.close()
    assert path.read_bytes() == damaged  # the damaged file is left as it was
    assert mcap_read(tmp_path / "j.part002.mcap") == 2  # the new part is valid MCAP
    chain = read_journal(path)
    assert chain.files == (path, tmp_path / "j.part002.mcap")
    assert revisions(chain)[-1] == EVENTS + 1 and len(chain.damage) == 1
    again = latest_state(chain)
    assert again.revision == EVENTS + 1 and again.lost is None
    assert [str(g.revisions) for g in again.gaps] == ["r110..r119"]
    with JournalWriter.resume(path) as resumed:  # a clean part is continued, not replaced
        assert not resumed.damaged and resumed.part_path == tmp_path / "j.part002.mcap"


def test_resume_without_damage_continues_the_same_file(tmp_path: Path) -> None:
    path = tmp_path / "j.mcap"
    write(path, "chunked", events=30)
    with JournalWriter.resume(path) as writer:
        assert not writer.damaged and not writer.needs_snapshot
        assert writer.part_path == path
        assert writer.recovered is not None and writer.recovered.damage == ()
        report = ResumeReport.of(path, (), latest_state(writer.recovered), path)
        assert report.clean and report.alert() == "" and report.log_line() == ""
        writer.append_event(event(31), T0 + 10**9)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["j.mcap"]
    assert mcap_read(path) == len(read_journal(path).records)


def test_reading_damage_logs_no_line_of_its_own(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    """Damage goes to whoever reads (one line with the revisions it cost), not to the log."""
    path = tmp_path / "j.mcap"
    rows = write(path, "chunked", events=30)
    flip(path, event_row(rows, 12).start + PAYLOAD["chunked"])
    with caplog.at_level(logging.WARNING):
        result = read_journal(path)
    assert len(result.damage) == 1
    assert [r.getMessage() for r in caplog.records] == [
        f"journal {path}: was not closed cleanly (no footer); recovered {len(result.records)} "
        "messages"
    ]
