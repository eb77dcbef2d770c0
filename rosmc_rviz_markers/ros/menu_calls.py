"""Menu choices that take more than one server call, made on the client's worker thread."""

from __future__ import annotations

import contextlib
from typing import Any

from rosmc_server.core import RosmcError
from rosmc_server.core.skills.params import value_to_data
from rosmc_server.ros.client import MissionClient

from ..core.menus import AddSkill


def add_driving_first(client: MissionClient, action: AddSkill, marker: str) -> Any:
    """The robot's move to ``marker``, then ``action``'s skill, both bound to it.

    Each call is made against the one before; a refused skill takes the move back, so the
    mission is as it was.
    """
    assert action.drive is not None and action.bind is not None
    move, target = action.drive
    moved = client.add_skill(action.agent, move, bindings={target: marker})
    try:
        values = {name: value_to_data(value) for name, value in action.values}
        return client.add_skill(action.agent, action.skill, values, bindings={action.bind: marker})
    except RosmcError:
        with contextlib.suppress(RosmcError):
            client.delete_skills([moved.skill_id])
        raise
