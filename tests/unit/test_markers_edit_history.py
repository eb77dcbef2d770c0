"""Undo and redo in rviz: every menu ends with both (the history is the shared one,
tested in ``test_edit_history.py``), and each menu entry says which edit it makes."""

from __future__ import annotations

from rosmc_rviz_markers.core.menus import (
    UNDO_MENU,
    AddSkill,
    DeleteMarker,
    RenameMarker,
    UndoEdit,
    flatten,
)
from rosmc_rviz_markers.core.requests import edit_kind
from rosmc_server.core.live.edit_history import EditKind


def test_every_menu_can_end_with_undo_and_redo() -> None:
    flat = flatten(UNDO_MENU)
    assert [(e.title, e.parent) for e in flat.entries] == [("Undo my last change", 0), ("Redo", 0)]
    assert list(flat.actions.values()) == [UndoEdit(), UndoEdit(redo=True)]


def test_each_menu_edit_has_its_kind() -> None:
    assert edit_kind(RenameMarker("Pose 2")) is EditKind.RENAME_MARKER
    assert edit_kind(DeleteMarker()) is EditKind.DELETE_MARKER
    assert edit_kind(AddSkill("drone", "navigate_to")) is EditKind.ADD_SKILL
