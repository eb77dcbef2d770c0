"""Reviewing a journal of many part files from the parts that hold the moment asked for.

A session of a real mission (adds, edits, deletes, an undo, a periodic snapshot journaled
late, a mission replacement) goes through the real :class:`MissionJournal` with small
parts (a part every 25 changes), so the journal holds several. ``rosmc at``, ``diff`` and
``restore`` read only the parts a moment needs (:mod:`rosmc_server.recording.moments`);
every revision and time they answer must be what reading the whole journal answers, on
an intact journal, one with damage in one part, and one whose last part a crash left.
No ROS master.
"""

from __future__ import annotations

import itertools
import shutil
import time
from collections.abc import Iterator
from pathlib import Path

import pytest

pytest.importorskip("rosmc.msg", reason="rosmc messages are not built (source build/devel)")

from rosmc_server.cli import main as rosmc
from rosmc_server.conversions import mission_to_msg
from rosmc_server.conversions.packing import serialized
from rosmc_server.core import Library, Mission, MissionEvent, RosmcError, load_library
from rosmc_server.interface import EVENTS_TOPIC, MISSION_TOPIC
from rosmc_server.recording import (
    JournalOptions,
    moments,
    read_journal,
)
from rosmc_server.recording._mcap.files import journal_parts
from rosmc_server.recording._mcap.opening import opening_snapshot
from rosmc_server.recording._mcap.scan import scan
from rosmc_server.recording.diff import resolve_when
from rosmc_server.recording.history import MissionHistory
from rosmc_server.recording.mission_journal import MissionJournal
from rosmc_server.recording.reader import JournalRecord, decode_scan

REPO = Path(__file__).resolve().parents[2]
OPTIONS = JournalOptions(fsync=False, snapshot_every=7, part_changes=25)
CHANGES = 130


def snapshot_of(mission: Mission) -> object:
    return mission_to_msg(mission.state.content(), mission.revision, 0.0)


def content_of(mission: Mission) -> bytes:
    return serialized(mission_to_msg(mission.state.content(), mission.revision, 0.0))


@pytest.fixture(scope="module")
def library() -> Library:
    return load_library(REPO / "tests" / "data" / "test_team.yaml")


@pytest.fixture(scope="module")
def session(
    library: Library, tmp_path_factory: pytest.TempPathFactory
) -> tuple[Path, dict[int, bytes]]:
    """A closed journal of several parts, and the live mission at every revision."""
    path = tmp_path_factory.mktemp("parts") / "m.mcap"
    mission = MissionJournal.new_mission(library)
    journal = MissionJournal.create(path, mission, OPTIONS)
    live = {mission.revision: content_of(mission)}

    def change(event: MissionEvent) -> None:
        journal.record(event, mission, snapshot_of)  # type: ignore[arg-type]
        live[event.revision] = content_of(mission)
        journal.writer.append_due_snapshot(snapshot_of(mission), time.time_ns())

    for number in range(CHANGES):
        agent = ("r1", "r2", "r3")[number % 3]
        task = mission.state.task(agent)
        if number == 60:  # a replacement: its event and snapshot are one unit
            replacement = MissionJournal.new_mission(library)
            for skill in range(5):
                replacement.add_skill("r2", "count", {"steps": skill + 1})
            change(mission.load(replacement.state.content(), "other.yaml"))
        elif number == 40:  # a periodic snapshot built before a change, journaled after it
            late = snapshot_of(mission)
            change(mission.add_skill(agent, "wait"))
            journal.writer.append_snapshot(late, time.time_ns())
        elif number % 11 == 5 and len(task) > 2:
            change(mission.delete_skills([task[1].id]))
        elif number % 13 == 7:
            change(mission.add_skill(agent, "wait"))
            change(mission.undo())
        elif number % 3 == 1 and any(skill.skill == "count" for skill in task):
            counting = [skill for skill in task if skill.skill == "count"][-1]
            change(mission.edit_skill(counting.id, {"steps": number % 40 + 1}))
        else:
            change(mission.add_skill(agent, "count", {"steps": number % 50 + 1}))
    journal.close()
    assert len(journal_parts(path)[1]) >= 5
    return path, live


def file_records(file: Path) -> tuple[JournalRecord, ...]:
    """The records of one part file alone."""
    return decode_scan(scan(file)).records


def moments_of(history: MissionHistory) -> Iterator[str]:
    """Every revision, and the seconds of every revision's time and between two."""
    infos = history.revisions
    for info in infos:
        yield f"r{info.revision}"
    for before, after in itertools.pairwise(infos):
        yield f"{history.seconds(before.log_time):.9f}"
        yield f"{history.seconds((before.log_time + after.log_time) // 2):.9f}"
    yield f"{history.duration + 5:.3f}"  # past the end: refused alike
    yield f"r{infos[-1].revision + 3}"  # never recorded: refused alike


def answer(history: MissionHistory, text: str) -> tuple[object, ...]:
    """What resolving ``text`` gives: the mission's bytes, label, time and revision info."""
    try:
        moment = resolve_when(history, text)
    except RosmcError as err:
        return (type(err).__name__,)
    state = moment.state
    info = next(r for r in history.revisions if r.revision == state.revision)
    content = serialized(mission_to_msg(state.content(), state.revision, 0.0))
    return (content, moment.label, moment.seconds, info)


def assert_parts_answer_as_the_whole(path: Path) -> int:
    """Every moment answered from the parts as from the whole journal; how many were
    answered from fewer revisions than the whole journal holds."""
    whole = MissionHistory.from_journal(path)
    fewer = 0
    for text in moments_of(whole):
        history = moments.review_histories(path, [text])[0]
        assert answer(history, text) == answer(whole, text), text
        fewer += len(history.revisions) < len(whole.revisions)
    return fewer


def test_each_part_opens_with_a_snapshot_read_from_its_first_bytes(
    session: tuple[Path, dict[int, bytes]],
) -> None:
    path, _ = session
    for _, file in journal_parts(path)[1]:
        first = next(r for r in file_records(file) if r.topic == MISSION_TOPIC)
        opening = opening_snapshot(file)
        assert opening is not None
        assert (opening.revision, opening.log_time) == (first.revision, first.log_time)
    found = moments.segments(path)
    assert found is not None and len(found) == len(journal_parts(path)[1])


def test_parts_hold_a_bounded_number_of_changes(session: tuple[Path, dict[int, bytes]]) -> None:
    path, _ = session
    for _, file in journal_parts(path)[1]:
        events = [r for r in file_records(file) if r.topic == EVENTS_TOPIC]
        assert len(events) <= OPTIONS.part_changes + OPTIONS.snapshot_every


def test_every_moment_from_the_parts_is_the_whole_journals(
    session: tuple[Path, dict[int, bytes]],
) -> None:
    path, live = session
    whole = MissionHistory.from_journal(path)
    for revision, content in live.items():  # the whole journal is the live mission
        state = whole.at_revision(revision)
        assert serialized(mission_to_msg(state.content(), revision, 0.0)) == content
    assert assert_parts_answer_as_the_whole(path) > len(live)  # most from a few parts


def test_damage_in_one_part_answers_as_the_whole_journal(
    session: tuple[Path, dict[int, bytes]], tmp_path: Path
) -> None:
    source, _ = session
    for _, file in journal_parts(source)[1]:
        shutil.copy(file, tmp_path / file.name)
    path = tmp_path / source.name
    damaged = journal_parts(path)[1][2][1]
    data = bytearray(damaged.read_bytes())
    data[len(data) * 2 // 3] ^= 0xFF  # an event's chunk: its CRC fails
    damaged.write_bytes(bytes(data))
    whole = MissionHistory.from_journal(path)
    assert whole.damage and whole.problems
    assert assert_parts_answer_as_the_whole(path) > 0


def test_a_crash_left_last_part_answers_as_the_whole_journal(
    session: tuple[Path, dict[int, bytes]], tmp_path: Path
) -> None:
    source, _ = session
    parts = journal_parts(source)[1]
    for _, file in parts:
        shutil.copy(file, tmp_path / file.name)
    path = tmp_path / source.name
    last = tmp_path / parts[-1][1].name
    events = [r for r in read_journal(last).records if r.topic == EVENTS_TOPIC]
    assert events  # the last part holds changes to cut into
    data = last.read_bytes()
    cut = data.rfind(b"\x06", 0, len(data) - 200)  # inside the data section, not the summary
    last.write_bytes(data[: max(cut, len(data) // 2)] + b"\x06\x40\x00")
    assert not read_journal(path).complete
    assert assert_parts_answer_as_the_whole(path) > 0


def test_cli_at_and_diff_print_the_same_from_the_parts(
    session: tuple[Path, dict[int, bytes]],
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    path, live = session
    middle, late = f"r{max(live) // 2}", f"r{max(live) - 3}"
    commands = [["at", str(path), middle], ["--json", "diff", str(path), "r3", late]]
    printed = []
    for command in commands:
        assert rosmc(command) == 0
        printed.append(capsys.readouterr().out)
    monkeypatch.setattr(moments, "segments", lambda _path: None)  # read whole
    for command, shown in zip(commands, printed, strict=True):
        assert rosmc(command) == 0
        assert capsys.readouterr().out == shown


def test_a_journal_of_one_file_is_read_whole(tmp_path: Path, library: Library) -> None:
    path = tmp_path / "one.mcap"
    mission = MissionJournal.new_mission(library)
    journal = MissionJournal.create(path, mission, JournalOptions(fsync=False))
    for _ in range(5):
        journal.record(mission.add_skill("r1", "wait"), mission, snapshot_of)  # type: ignore[arg-type]
    journal.close()
    assert moments.segments(path) is None
    history = moments.review_histories(path, ["r3"])[0]
    assert [r.revision for r in history.revisions] == list(
        range(mission.revision - 5, mission.revision + 1)
    )
