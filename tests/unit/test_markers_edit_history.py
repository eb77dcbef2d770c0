"""Undo and redo of this rviz's own edits: the history and the menu entries."""

from __future__ import annotations

from rosmc_rviz_markers.core.edit_history import EditHistory
from rosmc_rviz_markers.core.menus import UNDO_MENU, UndoEdit, flatten


def test_undo_takes_the_newest_edit_and_redo_takes_back_the_newest_undo() -> None:
    history = EditHistory()
    history.done(3, "add take_off to drone")
    history.done(5, "move Pose 1")
    assert history.take_undo() == (5, "move Pose 1")
    history.undone(6, "move Pose 1")
    assert history.take_redo() == (6, "move Pose 1")
    history.redone(7, "move Pose 1")
    assert history.take_undo() == (7, "move Pose 1")  # the redo can be undone again
    assert history.take_undo() == (3, "add take_off to drone")
    assert history.take_undo() is None and history.take_redo() is None


def test_a_new_edit_forgets_what_could_be_redone_and_clear_forgets_all() -> None:
    history = EditHistory()
    history.done(1, "a")
    history.undone(2, "a")
    history.done(3, "b")
    assert history.take_redo() is None
    history.clear()
    assert history.take_undo() is None


def test_every_menu_can_end_with_undo_and_redo() -> None:
    flat = flatten(UNDO_MENU)
    assert [(e.title, e.parent) for e in flat.entries] == [("Undo my last change", 0), ("Redo", 0)]
    assert list(flat.actions.values()) == [UndoEdit(), UndoEdit(redo=True)]
