"""The task-marker operations of :class:`~.mission_client.MissionClient` (its base class)."""

from __future__ import annotations

from collections.abc import Sequence

from ...conversions import marker_to_msg, pose_to_msg
from ...core import Pose, TaskMarker
from .base import ClientBase
from .results import MarkerAdded, Result


class MarkerCalls(ClientBase):
    """Add, move, rename and delete task markers (see :class:`~.mission_client.MissionClient`
    for the errors raised and what ``base_revision`` and ``retry_on_conflict`` do)."""

    def add_task_marker(
        self,
        marker: TaskMarker,
        *,
        base_revision: int | None = None,
        retry_on_conflict: bool = False,
    ) -> MarkerAdded:
        """Add a task marker (an empty name gets a generated one)."""
        response = self._mutate(
            "add_task_marker", base_revision, retry_on_conflict, marker=marker_to_msg(marker)
        )
        return MarkerAdded(response.revision, response.name)

    def move_task_marker(
        self,
        name: str,
        pose: Pose,
        vertices: Sequence[Pose] = (),
        *,
        base_revision: int | None = None,
        retry_on_conflict: bool = False,
    ) -> Result:
        """Move a task marker (an AREA by its ``vertices``); bound parameters follow."""
        response = self._mutate(
            "move_task_marker",
            base_revision,
            retry_on_conflict,
            name=name,
            pose=pose_to_msg(pose),
            vertices=[pose_to_msg(v) for v in vertices],
        )
        return Result(response.revision)

    def rename_task_marker(
        self,
        name: str,
        new_name: str,
        *,
        base_revision: int | None = None,
        retry_on_conflict: bool = False,
    ) -> Result:
        """Rename a task marker; bindings follow."""
        response = self._mutate(
            "rename_task_marker", base_revision, retry_on_conflict, name=name, new_name=new_name
        )
        return Result(response.revision)

    def delete_task_marker(
        self, name: str, *, base_revision: int | None = None, retry_on_conflict: bool = False
    ) -> Result:
        """Delete a task marker that no skill is bound to."""
        return Result(
            self._mutate("delete_task_marker", base_revision, retry_on_conflict, name=name).revision
        )
