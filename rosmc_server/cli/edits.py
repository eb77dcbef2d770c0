"""The commands that change the mission or control the robots."""

from __future__ import annotations

import os
import sys
from collections.abc import Callable
from pathlib import Path

from ..core import (
    InvalidRequest,
    LostLinkKind,
    LostLinkPolicy,
    LostLinkTrigger,
    MarkerType,
    MissionFileError,
    SkillSpec,
    TaskMarker,
)
from ..ros.client import ControlCommand
from .context import Context, UsageError
from .values import marker_shape, typed_values


def _values(spec: SkillSpec, words: list[str]) -> tuple[dict[str, object], dict[str, str | None]]:
    try:
        return typed_values(spec, words)
    except ValueError as error:
        raise UsageError(str(error)) from error


def add(ctx: Context) -> int:
    """Add a skill to a robot's blueprint; print its id."""
    args = ctx.args
    spec = ctx.client.library().skill(args.agent, args.skill)
    values, bindings = _values(spec, args.params)
    if any(marker is None for marker in bindings.values()):
        raise InvalidRequest("key=@ (unbind) applies to 'rosmc edit' only; give a marker name")
    result = ctx.client.add_skill(
        args.agent,
        args.skill,
        values,
        bindings={name: marker for name, marker in bindings.items() if marker},
        label=args.label,
        index=args.index,
        timeout=args.skill_timeout or 0.0,
        max_retries=args.retries or 0,
        **ctx.against(),
    )
    return ctx.emit_result(result, result.skill_id)


def edit(ctx: Context) -> int:
    """Change a blueprint skill's parameters, label or options."""
    args = ctx.args
    values, bindings = _values(ctx.client.skill_spec(args.skill_id), args.params)
    result = ctx.client.edit_skill(
        args.skill_id,
        values,
        bindings=bindings,
        label=args.label,
        timeout=args.skill_timeout,
        max_retries=args.retries,
        **ctx.against(),
    )
    return ctx.emit_result(result)


def delete(ctx: Context) -> int:
    """Delete blueprint skills."""
    return ctx.emit_result(ctx.client.delete_skills(ctx.args.skill_ids, **ctx.against()))


def reorder(ctx: Context) -> int:
    """Give a robot's blueprint a new order."""
    args = ctx.args
    return ctx.emit_result(ctx.client.reorder_skills(args.agent, args.order, **ctx.against()))


def barrier(ctx: Context) -> int:
    """Add a barrier; print its id."""
    result = ctx.client.add_barrier(ctx.args.skill_ids, **ctx.against())
    return ctx.emit_result(result, result.barrier_id)


def delete_barrier(ctx: Context) -> int:
    """Remove a barrier."""
    result = ctx.client.delete_barrier(ctx.args.barrier_id, **ctx.against())
    return ctx.emit_result(result)


def undo(ctx: Context) -> int:
    """Undo an edit (the latest not undone, or the one that produced REVISION)."""
    result = ctx.client.undo_edit(ctx.args.undo_revision, **ctx.against())
    return ctx.emit_result(result, f"revision {result.revision}: {result.summary}")


def sync(ctx: Context) -> int:
    """Upload a robot's blueprint (up to --upto), or every robot's at once (--all)."""
    args = ctx.args
    uptos = args.upto or []
    if args.team:
        return sync_team(ctx, uptos)
    if not args.agent or len(uptos) > 1:
        raise InvalidRequest("name one robot (and at most one --upto), or give --all")
    result = ctx.client.synchronize(args.agent, uptos[0] if uptos else None, **ctx.against())
    ids = ", ".join(result.skill_ids)
    return ctx.emit_result(result, f"uploading to {args.agent}: {ids} (revision {result.revision})")


def sync_team(ctx: Context, uptos: list[str]) -> int:
    """Upload every robot's blueprint in one change; each --upto stops its own robot early."""
    if ctx.args.agent:
        raise InvalidRequest("--all sends every robot; name no robot with it")
    state = ctx.client.get_mission()
    uploads: dict[str, str | None] = {}
    for agent in state.agents:
        if state.sections(agent).editable_start < len(state.task(agent)):
            uploads[agent] = None
    for upto in uptos:
        agent, _ = state.locate(upto)  # NotFound for an unknown id
        uploads[agent] = upto
    result = ctx.client.synchronize_team(uploads, **ctx.against())
    lines = [
        f"uploading to {agent}: "
        + ", ".join(i for i in result.skill_ids if state.locate(i)[0] == agent)
        for agent in result.agents
    ]
    lines.append(f"(revision {result.revision})")
    return ctx.emit_result(result, "\n".join(lines))


def unsync(ctx: Context) -> int:
    """Pull synchronized skills back to the blueprint."""
    args = ctx.args
    result = ctx.client.unsynchronize(args.agent, args.from_id, **ctx.against())
    ids = ", ".join(result.skill_ids)
    return ctx.emit_result(
        result, f"removing from {args.agent}: {ids} (revision {result.revision})"
    )


def control(ctx: Context) -> int:
    """Start, pause, resume or stop robots."""
    command = ControlCommand[ctx.args.command.upper()]
    result = ctx.client.control(command, ctx.args.agent)
    return ctx.emit_result(result, f"{ctx.args.command} sent to {', '.join(result.agents)}")


def lost_link_policy(ctx: Context) -> int:
    """Set a robot's lost-link policy."""
    args = ctx.args
    kind = LostLinkKind(args.kind)
    if kind.runs_skill != bool(args.skill):
        raise UsageError("--skill names the skill, and goes with safe_skill or return_to_link only")
    values: dict[str, object] = {}
    if args.params:
        if not args.skill:
            raise UsageError("--param goes with --skill only")
        values, bindings = _values(ctx.client.library().skill(args.agent, args.skill), args.params)
        if bindings:
            raise InvalidRequest("safe-skill parameters cannot be bound to task markers")
    chosen = LostLinkPolicy(kind, args.after, args.skill, values, LostLinkTrigger(args.when))
    result = ctx.client.set_lost_link_policy(args.agent, chosen)
    return ctx.emit_result(result, f"{args.agent}: {chosen.describe()} (sent to the robot)")


def retry(ctx: Context) -> int:
    """Retry a failed skill; print the new instance's id."""
    result = ctx.client.retry_skill(ctx.args.skill_id, **ctx.against())
    return ctx.emit_result(result, result.new_skill_id)


def skip(ctx: Context) -> int:
    """Skip a failed skill."""
    return ctx.emit_result(ctx.client.skip_skill(ctx.args.skill_id, **ctx.against()))


def marker(ctx: Context) -> int:
    """Add, move, rename or delete a task marker."""
    args, client, base = ctx.args, ctx.client, ctx.against()
    if args.marker_command == "add":
        kind = MarkerType[args.type.upper()]
        pose, vertices = marker_shape(kind, args.where, f"the {args.type} of the marker")
        added = client.add_task_marker(TaskMarker(args.name, kind, pose, vertices), **base)
        return ctx.emit_result(added, added.name)
    if args.marker_command == "move":
        old = next((m for m in client.fetch_mission().markers if m.name == args.name), None)
        kind = old.type if old is not None else MarkerType.POSE  # the server names a missing one
        pose, vertices = marker_shape(kind, args.where, f"the new place of '{args.name}'")
        return ctx.emit_result(client.move_task_marker(args.name, pose, vertices, **base))
    if args.marker_command == "rename":
        return ctx.emit_result(client.rename_task_marker(args.name, args.new_name, **base))
    return ctx.emit_result(client.delete_task_marker(args.name, **base))


def new(ctx: Context) -> int:
    """Start an empty mission."""
    keep = not ctx.args.drop_markers
    return ctx.emit_result(ctx.client.new_mission(keep_markers=keep, **ctx.against()))


def save(ctx: Context) -> int:
    """Write the mission as YAML into a local file (or standard output), or on the server."""
    if ctx.args.on_server:
        written = ctx.client.save_mission(ctx.args.file)
        return ctx.emit_result(
            written, f"saved revision {written.revision} to {written.path_written} on the server"
        )
    saved = ctx.client.save_mission()
    if ctx.args.file == "-":
        sys.stdout.write(saved.document)
        sys.stdout.flush()
        return 0
    target = Path(ctx.args.file)
    temporary = target.with_name(f".{target.name}.{os.getpid()}.tmp")
    try:
        temporary.write_text(saved.document, encoding="utf-8")
        temporary.replace(target)
    except OSError as error:
        temporary.unlink(missing_ok=True)
        raise MissionFileError(f"{target}: cannot write the mission ({error.strerror})") from error
    return ctx.emit_result(saved, f"saved revision {saved.revision} to {target}")


def load(ctx: Context) -> int:
    """Replace the mission with a saved one read from a local file (or standard input)."""
    name = ctx.args.file
    if ctx.args.on_server:
        return ctx.emit_result(ctx.client.load_mission(path=name, **ctx.against()))
    try:
        document = sys.stdin.read() if name == "-" else Path(name).read_text(encoding="utf-8")
    except OSError as error:
        raise MissionFileError(f"{name}: cannot read the mission ({error.strerror})") from error
    except UnicodeDecodeError as error:
        raise MissionFileError(f"{name}: the file is not UTF-8 text") from error
    return ctx.emit_result(ctx.client.load_mission(document, **ctx.against()))


COMMANDS: dict[str, Callable[[Context], int]] = {
    "add": add,
    "edit": edit,
    "delete": delete,
    "reorder": reorder,
    "barrier": barrier,
    "delete-barrier": delete_barrier,
    "unbarrier": delete_barrier,
    "undo": undo,
    "sync": sync,
    "unsync": unsync,
    "start": control,
    "pause": control,
    "resume": control,
    "stop": control,
    "lost-link-policy": lost_link_policy,
    "retry": retry,
    "skip": skip,
    "marker": marker,
    "new": new,
    "save": save,
    "load": load,
}
