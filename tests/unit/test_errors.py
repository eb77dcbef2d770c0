"""The error family: one root, one-line messages whatever a request quotes."""

from __future__ import annotations

import pickle
from typing import Any

import pytest

from rosmc_server.core import (
    InvalidRequest,
    LibraryError,
    MissionFileError,
    NotFound,
    RosmcError,
    RuleViolation,
    StaleRevision,
    Unavailable,
)

CLASSES = [InvalidRequest, NotFound, RuleViolation, Unavailable, LibraryError, MissionFileError]


@pytest.mark.parametrize("kind", CLASSES)
def test_every_error_is_a_rosmc_error(kind: Any) -> None:
    error = kind("something went wrong")
    assert isinstance(error, RosmcError) and str(error) == "something went wrong"
    assert str(pickle.loads(pickle.dumps(error))) == "something went wrong"


def test_stale_revision_names_both_revisions() -> None:
    error = StaleRevision(3, 7)
    assert (error.base_revision, error.current_revision) == (3, 7)
    assert "revision 3" in str(error) and "revision 7" in str(error)
    assert isinstance(error, RosmcError)
    assert "rosmc status" in str(error), "the hint names a real command"


def test_a_revision_from_the_future_is_called_so() -> None:
    message = str(StaleRevision(2**63, 69))
    assert message.startswith("revision 9223372036854775808 is ahead of the mission"), message
    assert "changed since" not in message


@pytest.mark.parametrize("name", ["a\nb", "a\r\nb", "a\u2028b", "a\x0bb", "a\x85b", "tab\there"])
def test_quoted_names_cannot_break_the_line(mission: Any, rejected: Any, name: str) -> None:
    for operation, args in (
        (mission.edit_skill, (name,)),
        (mission.delete_marker, (name,)),
        (mission.stop, (name,)),
        (mission.add_skill, ("alpha", name)),
        (mission.add_skill, ("alpha", "move", {name: 1})),
    ):
        error = rejected(mission, NotFound, operation, *args)
        assert len(str(error).splitlines()) == 1


def test_plain_text_is_kept_as_it_is() -> None:
    text = "ünïcode — “quotes” and spaces stay"
    assert str(RuleViolation(text)) == text
