"""The edit history both GUIs keep (rosmc_server.core.live.edit_history): its one rule.

Only requests whose kind is an edit are kept; undo and redo go one at a time, against the
revision the operator saw; a conflict or no answer keeps the entry (and says so), a
refusal by the mission rules drops it (and gives the server's reason). Joined edits (a
Duplicate's copies) are one entry, undone one revision after the other.
"""

from __future__ import annotations

import pytest

from rosmc_server.core import RuleViolation, StaleRevision
from rosmc_server.core.errors import ServerUnavailable
from rosmc_server.core.live.edit_history import EditHistory, EditKind, Entry, Failure, failure_of


def test_only_edits_are_kept_and_a_new_edit_forgets_the_redo() -> None:
    history = EditHistory()
    assert not history.done(None, 2, "synchronize drone")  # not an edit: nothing to undo
    assert history.next_undo() is None
    assert history.done(EditKind.ADD_SKILL, 3, "add take_off to drone")
    step = history.begin(redo=False, seen=3)
    assert step is not None
    history.accepted(step, 4)
    assert history.next_redo() == Entry((4,), "add take_off to drone")
    history.done(EditKind.MOVE_MARKER, 5, "move 'Pose 1'")
    assert history.next_redo() is None
    assert history.next_undo() == Entry((5,), "move 'Pose 1'")


def test_undo_takes_the_newest_edit_and_redo_takes_back_the_newest_undo() -> None:
    history = EditHistory()
    history.done(EditKind.ADD_SKILL, 3, "add take_off to drone")
    history.done(EditKind.MOVE_MARKER, 5, "move 'Pose 1'")
    undo = history.begin(redo=False, seen=5)
    assert undo is not None and undo.entry == Entry((5,), "move 'Pose 1'")
    assert undo.words == "undo move 'Pose 1'" and undo.base_revision == 5
    history.accepted(undo, 6)
    redo = history.begin(redo=True, seen=6)
    assert redo is not None and redo.entry == Entry((6,), "move 'Pose 1'")
    assert redo.words == "redo move 'Pose 1'"
    history.accepted(redo, 7)
    assert history.next_undo() == Entry((7,), "move 'Pose 1'")  # the redo can be undone again
    assert history.next_redo() is None


def test_one_step_at_a_time() -> None:
    history = EditHistory()
    history.done(EditKind.ADD_SKILL, 3, "a")
    history.done(EditKind.ADD_SKILL, 4, "b")
    step = history.begin(redo=False, seen=4)
    assert step is not None and history.busy
    assert history.begin(redo=False, seen=4) is None  # the first is on its way
    history.accepted(step, 5)
    assert not history.busy
    assert history.begin(redo=False, seen=5) is not None


@pytest.mark.parametrize("failure", [Failure.CONFLICT, Failure.UNREACHABLE])
def test_a_conflict_or_no_answer_keeps_the_entry_and_says_why(failure: Failure) -> None:
    history = EditHistory()
    history.done(EditKind.DELETE_SKILLS, 8, "delete 'take_off'")
    step = history.begin(redo=False, seen=8)
    assert step is not None
    sentence = history.failed(step, failure)
    assert sentence == f"Could not undo delete 'take_off' ({failure.value}); it is kept: try again"
    assert history.next_undo() == Entry((8,), "delete 'take_off'") and not history.busy
    again = history.begin(redo=False, seen=9)  # tried again against what is shown now
    assert again is not None and again.base_revision == 9


def test_a_refusal_drops_the_entry_with_the_servers_reason() -> None:
    history = EditHistory()
    history.done(EditKind.ADD_SKILL, 3, "add take_off to drone")
    history.done(EditKind.EDIT_SKILL, 4, "change altitude of 'take_off'")
    step = history.begin(redo=False, seen=4)
    assert step is not None
    reason = "skill 'drone-1' has been sent to drone since revision 4"
    sentence = history.failed(step, Failure.REFUSED, reason)
    assert sentence == f"Could not undo change altitude of 'take_off': {reason}"
    assert history.next_undo() == Entry((3,), "add take_off to drone")


def test_a_failed_redo_goes_back_to_the_redo_stack() -> None:
    history = EditHistory()
    history.done(EditKind.RENAME_MARKER, 3, "rename")
    undo = history.begin(redo=False, seen=3)
    assert undo is not None
    history.accepted(undo, 4)
    redo = history.begin(redo=True, seen=4)
    assert redo is not None
    history.failed(redo, Failure.CONFLICT)
    assert history.next_redo() == Entry((4,), "rename") and history.next_undo() is None


def test_errors_map_to_failures() -> None:
    assert failure_of(StaleRevision(3, 5)) is Failure.CONFLICT
    assert failure_of(ServerUnavailable("no answer")) is Failure.UNREACHABLE
    assert failure_of(RuleViolation("sent since")) is Failure.REFUSED


def test_a_new_server_shows_in_revisions_above_its_own_and_clear_forgets_all() -> None:
    history = EditHistory()
    history.done(EditKind.ADD_MARKER, 12, "new pose marker")
    assert history.newest_above(5) and not history.newest_above(12)
    history.begin(redo=False, seen=12)
    history.clear()
    assert history.next_undo() is None and not history.busy


def test_joined_edits_are_one_entry_undone_newest_first() -> None:
    history = EditHistory()
    history.done(EditKind.ADD_SKILL, 3, "add take_off to drone")
    for revision in (5, 6, 7):
        history.done(EditKind.ADD_SKILL, revision, "duplicate take_off")
    assert not history.join([4, 6, 7], "duplicate 3 skills")  # not the newest edits
    assert history.join([5, 6, 7], "duplicate 3 skills")
    step = history.begin(redo=False, seen=7)
    assert step is not None and step.next_revision == 7
    assert history.accepted(step, 8) == 6 and history.busy  # the next copy back
    assert history.accepted(step, 9) == 5
    assert history.accepted(step, 10) is None and not history.busy
    assert history.next_redo() == Entry((10, 9, 8), "duplicate 3 skills")
    redo = history.begin(redo=True, seen=10)
    assert redo is not None and redo.next_revision == 10


def test_a_joined_undo_cut_short_keeps_what_is_left_and_what_was_undone() -> None:
    history = EditHistory()
    for revision in (5, 6, 7):
        history.done(EditKind.ADD_SKILL, revision, "duplicate")
    history.join([5, 6, 7], "duplicate 3 skills")
    step = history.begin(redo=False, seen=7)
    assert step is not None
    assert history.accepted(step, 8) == 6
    history.failed(step, Failure.CONFLICT)
    assert history.next_undo() == Entry((6, 5), "duplicate 3 skills")  # tried again later
    assert history.next_redo() == Entry((8,), "duplicate 3 skills")  # the copy taken back
