"""What an operator service request's fields mean when a caller leaves them out.

A ROS 1 request has no optional fields: an omitted ``uint64`` or ``int32`` arrives as 0.
So 0 is the value a person typing ``rosservice call /rosmc/add_skill "{agent: drone,
skill: take_off}"`` sends, and it means what they would expect:

- ``base_revision`` 0: no revision check (the change is made against whatever the mission
  is now). The GUIs and the Python client send the revision their view was made at, and a
  stale one is refused (``CONFLICT``) as before. No mission is ever at revision 0: a fresh
  one starts at :data:`FIRST_REVISION`, its first journal record, so every real view is
  checked.
- ``AddSkill.index`` 0: append at the end of the agent's task. ``-1`` appends too (what
  clients sent before); ``n >= 1`` inserts at task position ``n`` (counting from 0), as
  before; :data:`FRONT` (any value below -1) inserts at position 0, the front of the task.
"""

from __future__ import annotations

from typing import Any, Final

from ..core import InvalidRequest

NO_CHECK: Final = 0
"""``base_revision`` that asks for no revision check (what an omitted field sends)."""

FIRST_REVISION: Final = 1
"""The revision of a fresh mission (above :data:`NO_CHECK`, which no view is ever at)."""

APPEND: Final = 0
"""``AddSkill.index`` that appends (what an omitted field sends); -1 appends too."""

FRONT: Final = -2
"""``AddSkill.index`` that inserts at position 0 (any value below -1 does)."""


def base_revision_from_msg(value: int) -> int | None:
    """The revision a request was made against, or None for no check."""
    return None if value == NO_CHECK else int(value)


def base_of(request: Any) -> int | None:
    """:func:`base_revision_from_msg` of a request's ``base_revision`` field."""
    return base_revision_from_msg(request.base_revision)


def insert_index_from_msg(value: int) -> int | None:
    """The task position an ``AddSkill`` inserts at, or None to append."""
    if value in (APPEND, -1):
        return None
    return 0 if value < -1 else int(value)


def insert_index_to_msg(index: int | None) -> int:
    """The wire value of task position ``index`` (None: append).

    Raises:
        InvalidRequest: ``index`` is negative.
    """
    if index is None:
        return APPEND
    if index < 0:
        raise InvalidRequest(f"a task position counts from 0, got {index}")
    return FRONT if index == 0 else index
