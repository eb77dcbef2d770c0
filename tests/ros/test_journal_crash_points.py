"""Crash points: no acknowledged change is lost, and no revision number names two missions,
wherever a crash, a cut or a lost side file strikes.

A scripted session (adds, an edit, an undo, a periodic snapshot journaled late, a load of
a 250-skill mission that starts a new part file, a team synchronize, the robot's answer,
more edits, due snapshots) runs through the real :class:`MissionJournal` with a real
mission, while a test file layer (:mod:`tests.ros.file_layer`) logs every write. Then:

* **process crash** at every write (before it, and torn in its middle): the folder is
  rebuilt as the crash left it, the journal resumed, two more changes made, the process
  crashed again and the journal resumed again. Every acknowledged revision is there with
  identical content, the resumed mission is the last acknowledged one (or the next, if its
  record was down in full), nothing is reported lost, and the new revisions are new;
* **the journal's end lost** (cut or zeroed at every write, the side file and the head as
  they were at the end), with the side file also deleted, emptied or garbled: the loss is
  named in the alert ``rosmc status`` and both GUIs show, and no acknowledged revision
  number is handed out again;
* **a damaged header** (one bit at offsets 0, 8, 17, 21): the resume goes on.

``make test`` checks a fixed sample of the points; ``make test-thorough``
(``HYPOTHESIS_PROFILE=thorough``) checks all of them.
"""

from __future__ import annotations

import os
import shutil
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path

import pytest

pytest.importorskip("rosmc.msg", reason="rosmc messages are not built (source build/devel)")

from rosmc_server.conversions import mission_to_msg
from rosmc_server.conversions.packing import serialized
from rosmc_server.conversions.request_fields import FIRST_REVISION
from rosmc_server.core import Library, Mission, MissionEvent, load_library
from rosmc_server.recording import JournalError, JournalOptions
from rosmc_server.recording.history import MissionHistory
from rosmc_server.recording.mission_journal import MissionJournal, Resumed
from tests.ros.file_layer import FileLog

REPO = Path(__file__).resolve().parents[2]
NAME = "mission.mcap"
OPTIONS = JournalOptions(snapshot_every=6, part_bytes=12_000)
THOROUGH = os.environ.get("HYPOTHESIS_PROFILE") == "thorough"
SAMPLE = 1 if THOROUGH else 5  # every point, or every fifth write (and every replacement's)


@dataclass(frozen=True)
class Acked:
    """A change the journal acknowledged: its revision and the mission it made."""

    revision: int
    content: bytes


@pytest.fixture(scope="module")
def library() -> Library:
    return load_library(REPO / "tests" / "data" / "test_team.yaml")


def content_of(mission: Mission) -> bytes:
    """The mission as bytes, to compare (stamp left out)."""
    return serialized(mission_to_msg(mission.state.content(), mission.revision, 0.0))


def snapshot_of(mission: Mission) -> object:
    return mission_to_msg(mission.state.content(), mission.revision, 0.0)


class Session:
    """A mission and its journal, noting every acknowledged change in the file log."""

    def __init__(self, folder: Path, library: Library, log: FileLog) -> None:
        self.log = log
        self.library = library
        self.mission = MissionJournal.new_mission(library)
        self.journal = MissionJournal.create(folder / NAME, self.mission, OPTIONS)
        log.note(Acked(self.mission.revision, content_of(self.mission)))

    def change(self, operation: Callable[[Mission], MissionEvent]) -> MissionEvent:
        event = operation(self.mission)
        self.journal.record(event, self.mission, snapshot_of)  # type: ignore[arg-type]
        self.log.note(Acked(event.revision, content_of(self.mission)))
        self.journal.writer.append_due_snapshot(snapshot_of(self.mission), 0)
        return event

    def first_skill(self, agent: str) -> str:
        return self.mission.state.task(agent)[0].id


def big_mission(library: Library, skills: int) -> Mission:
    mission = MissionJournal.new_mission(library)
    for number in range(skills):
        mission.add_skill(("r1", "r2", "r3")[number % 3], "count", {"steps": number % 50 + 1})
    return mission


@pytest.fixture(scope="module")
def session_log(
    library: Library, tmp_path_factory: pytest.TempPathFactory
) -> Iterator[tuple[FileLog, dict[int, bytes]]]:
    """The file log of the scripted session, and every acknowledged revision's mission."""
    folder = tmp_path_factory.mktemp("session")
    log = FileLog(folder)
    with pytest.MonkeyPatch.context() as patch, log.recording(patch):
        s = Session(folder, library, log)
        for agent, skill in (("r1", "wait"), ("r1", "wait"), ("r2", "probe"), ("r1", "count")):
            s.change(lambda m, a=agent, k=skill: m.add_skill(a, k))
        s.change(lambda m: m.edit_skill(s.first_skill("r1"), {"duration": 1.5}))
        s.change(lambda m: m.undo())
        late = snapshot_of(s.mission)  # built off the lock; a change is journaled meanwhile
        s.change(lambda m: m.add_skill("r3", "wait"))
        s.journal.writer.append_snapshot(late, 0)
        loaded = big_mission(library, 250).state.content()
        s.change(lambda m: m.load(loaded, "big.yaml"))
        s.change(lambda m: m.add_skill("r2", "wait", {"duration": 2.0}))
        s.change(lambda m: m.synchronize_team())
        synced = [skill.id for skill in s.mission.state.task("r1")[:3]]
        s.change(lambda m: m.confirm_synchronized("r1", synced))
        for number in range(8):
            s.change(lambda m, n=number: m.add_skill("r3", "count", {"steps": n + 1}))
        s.change(lambda m: m.delete_skills([s.mission.state.task("r3")[-1].id]))
        s.journal.writer.abandon()  # the session ends in a crash, not a close
        s.journal.marks.close()
    truth = {label.revision: label.content for label in log.notes_before(len(log.ops))}
    assert len(truth) == 21 and (folder / "mission.part002.mcap").exists()  # a rollover
    yield log, truth


def crash_points(log: FileLog) -> list[tuple[int, int]]:
    """(ops before the crash, bytes of the interrupted write): before every write, and
    torn in its middle; sampled unless thorough (every big write always).

    The side file's one-line rewrite is not torn: a write of under a sector in place
    happens whole or not at all, even at a power loss (the head's slots are torn: it
    keeps two).
    """
    points = []
    writes = [i for i, op in enumerate(log.ops) if op.kind == "write"]
    for number, index in enumerate(writes):
        op = log.ops[index]
        if number % SAMPLE and len(op.data) < 4096:
            continue
        points.append((index, 0))
        if not op.name.endswith(".revisions"):
            points.append((index, max(1, len(op.data) // 2)))
    return [*points, (len(log.ops), 0)]


def resume(folder: Path, library: Library) -> Resumed:
    return MissionJournal.resume(folder / NAME, library, OPTIONS)


def assert_history_holds(folder: Path, acked: list[Acked], upto: int) -> None:
    """Every acknowledged revision up to ``upto`` reads back with identical content."""
    history = MissionHistory.from_journal(folder / NAME)
    for change in acked:
        if change.revision <= upto:
            state = history.at_revision(change.revision)
            got = serialized(mission_to_msg(state.content(), state.revision, 0.0))
            assert got == change.content, f"r{change.revision} differs"


def continue_and_crash_again(resumed: Resumed, library: Library, folder: Path) -> list[Acked]:
    """Two more acknowledged changes, a second crash, a second resume: nothing lost."""
    made = []
    for skill in ("wait", "probe"):
        event = resumed.mission.add_skill("r2", skill)
        resumed.journal.record(event, resumed.mission, snapshot_of)  # type: ignore[arg-type]
        made.append(Acked(event.revision, content_of(resumed.mission)))
    resumed.journal.writer.abandon()
    resumed.journal.marks.close()
    again = resume(folder, library)
    try:
        assert again.report.alert() == "", again.report.alert()
        assert again.mission.revision == made[-1].revision
        assert content_of(again.mission) == made[-1].content
    finally:
        again.journal.close()
    return made


def test_a_crash_at_any_write_loses_no_acknowledged_change(
    session_log: tuple[FileLog, dict[int, bytes]], library: Library, tmp_path: Path
) -> None:
    log, truth = session_log
    checked = 0
    for upto, torn in crash_points(log):
        folder = tmp_path / f"crash-{upto}-{torn}"
        log.rebuild(upto, torn, folder)
        acked: list[Acked] = log.notes_before(upto)
        try:
            resumed = resume(folder, library)
        except JournalError:  # the journal was being created: nothing was acknowledged yet
            assert not acked, f"crash before op {upto} (+{torn} bytes)"
            continue
        last = acked[-1].revision if acked else FIRST_REVISION
        where = f"crash before op {upto} (+{torn} bytes)"
        assert resumed.report.alert() == "", f"{where}: {resumed.report.alert()}"
        revision = resumed.mission.revision
        assert revision in (last, last + 1), f"{where}: resumed at r{revision}, acked r{last}"
        assert content_of(resumed.mission) == truth[revision], where
        made = continue_and_crash_again(resumed, library, folder)
        assert made[0].revision == revision + 1, where
        assert_history_holds(folder, acked + made, made[-1].revision)
        checked += 1
        shutil.rmtree(folder)
    assert checked >= (40 if not THOROUGH else 150)


@pytest.mark.parametrize("side_file", ["kept", "deleted", "emptied", "garbled"])
@pytest.mark.parametrize("how", ["cut", "zeroed"])
def test_a_journal_that_lost_its_end_names_the_loss_and_reuses_no_revision(
    session_log: tuple[FileLog, dict[int, bytes]],
    library: Library,
    tmp_path: Path,
    how: str,
    side_file: str,
) -> None:
    log, truth = session_log
    top = max(truth)
    writes = [i for i, op in enumerate(log.ops) if op.kind == "write" and op.name.endswith(".mcap")]
    for number, index in enumerate(writes[:: SAMPLE * 2]):
        op = log.ops[index]
        folder = tmp_path / f"{how}-{side_file}-{number}"
        log.rebuild(len(log.ops), 0, folder)  # the end as it was, side file and head included
        lose_from(folder, op.name, op.offset + len(op.data) // 2, how)
        mark = folder / f"{NAME}.revisions"
        if side_file == "deleted":
            mark.unlink()
        elif side_file == "emptied":
            mark.write_bytes(b"")
        elif side_file == "garbled":
            mark.write_bytes(b"\x13" * 128)
        where = f"{how} in {op.name} at {op.offset + len(op.data) // 2}, side file {side_file}"
        try:
            resumed = resume(folder, library)
        except JournalError as err:  # the first file lost its first snapshot: nothing to resume
            assert op.name == NAME and "holds no mission snapshot" in str(err), where
            continue
        kept = resumed.mission.revision
        if kept < top or side_file != "kept":
            assert resumed.report.alert(), f"{where}: nothing said"
        event = resumed.mission.add_skill("r1", "wait")
        assert event.revision > top, f"{where}: r{event.revision} was handed out before"
        resumed.journal.close()
        shutil.rmtree(folder)


def lose_from(folder: Path, name: str, offset: int, how: str) -> None:
    """Cut (or zero) the journal from ``offset`` of file ``name`` on, later parts included."""
    path = folder / name
    size = path.stat().st_size
    with path.open("r+b") as file:
        file.truncate(offset)
        if how == "zeroed":
            file.seek(offset)
            file.write(b"\0" * (size - offset))
    number = 2 if name == NAME else int(name.split(".part")[1][:3]) + 1
    while (later := folder / f"mission.part{number:03d}.mcap").exists():
        later.unlink()
        number += 1


@pytest.mark.parametrize("offset", [0, 8, 17, 21])
def test_a_flipped_bit_in_the_header_does_not_stop_the_resume(
    session_log: tuple[FileLog, dict[int, bytes]], library: Library, tmp_path: Path, offset: int
) -> None:
    log, truth = session_log
    log.rebuild(len(log.ops), 0, tmp_path)
    path = tmp_path / NAME
    data = bytearray(path.read_bytes())
    data[offset] ^= 0x04
    path.write_bytes(bytes(data))
    resumed = resume(tmp_path, library)
    assert resumed.mission.revision == max(truth)
    assert content_of(resumed.mission) == truth[max(truth)]
    resumed.journal.close()
