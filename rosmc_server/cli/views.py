"""The read-only commands: status, library, markers and watch."""

from __future__ import annotations

import json
import sys
import time

from ..core import AgentStatus, MissionEvent
from ..core.world.site_source import site_line
from ..ros.client import MissionWatch, ServerUnavailable, init_node
from ..text import (
    agent_status_to_json,
    event_to_json,
    format_agent_status,
    format_event,
    format_library,
    format_markers,
    format_tasks,
    library_to_json,
    marker_to_json,
    mission_to_json,
    site_to_json,
)
from .context import Context


def status(ctx: Context) -> int:
    """Every robot's task with its link and telemetry line, the science score if published,
    the site map in force (and a journal alert first)."""
    state = ctx.client.get_mission()
    library = ctx.client.library()
    statuses = None if ctx.args.no_states else ctx.agent_states()
    alert = ctx.client.journal_alert
    science = None if ctx.args.no_states else ctx.science()
    site = None if ctx.args.no_states else ctx.site()
    if ctx.json:
        data = {**mission_to_json(state, library, statuses), "journal_alert": alert}
        data["site"] = site_to_json(site) if site else None
        ctx.emit("", {**data, "science": science.to_dict() if science else None})
        return 0
    text = format_tasks(state, statuses=statuses, verbose=ctx.args.verbose)
    if science is not None:  # what the mission is for, under the tasks' first line
        first, _, rest = text.partition("\n")
        text = "\n".join([first, *science.lines(), rest])
    if alert:  # first, where nobody misses it
        text = f"{alert}\n{text}"
    if state.markers:
        markers = format_markers(state.markers).splitlines()
        text += "\n  task markers\n" + "\n".join(f"    {line}" for line in markers)
    if not ctx.args.no_states:  # the map targets are checked against, and who sent it
        text += f"\n{site_line(site)}"
    ctx.emit(text, None)
    return 0


def library(ctx: Context) -> int:
    """The agents, their skills and every parameter's schema."""
    lib = ctx.client.library()
    agent = ctx.args.agent
    if agent:
        lib.agent(agent)  # NotFound names the known agents
    data = library_to_json(lib)
    if agent:
        data["agents"] = [entry for entry in data["agents"] if entry["name"] == agent]
    ctx.emit(format_library(lib, agent), data)
    return 0


def markers(ctx: Context) -> int:
    """The task markers."""
    state = ctx.client.get_mission()
    ctx.emit(format_markers(state.markers), [marker_to_json(m) for m in state.markers])
    return 0


def watch(ctx: Context) -> int:
    """Print mission events (and robot states) until Ctrl-C or --count events.

    The revision it starts from is fetched once the subscriber is connected (as the
    mirror does), so every event after it is heard: none falls between the two.
    """
    ctx.client.get_mission()  # fails fast (exit 3) if the server is not there
    init_node()
    interval = ctx.args.states
    watcher = MissionWatch(events=True, states=interval is not None)
    try:
        if not watcher.wait_connected(ctx.client.timeout):
            raise ServerUnavailable(
                f"the mission server's topics did not connect within {ctx.client.timeout:g} s"
            )
        state = ctx.client.get_mission()  # events up to here are in it; later ones are heard
        print(
            f"rosmc: watching mission events from revision {state.revision} (Ctrl-C to stop)",
            file=sys.stderr,
            flush=True,
        )
        _watch_loop(ctx, watcher, interval, state.revision)
    except KeyboardInterrupt:
        pass
    finally:
        watcher.close()
    return 0


def _watch_loop(ctx: Context, watcher: MissionWatch, interval: float | None, revision: int) -> None:
    """Print the events after ``revision`` (those heard before the fetch are in it)."""
    remaining = ctx.args.count
    last_states = -float("inf")
    printed = False
    while remaining is None or remaining > 0:
        event = watcher.next_event(timeout=0.2)
        if event is not None and (printed or event.revision > revision):
            if event.revision > revision + 1:  # the server's publisher queue overflowed
                print(
                    f"rosmc: warning: revisions {revision + 1} to {event.revision - 1} were "
                    "not heard; 'rosmc status' shows the mission",
                    file=sys.stderr,
                    flush=True,
                )
            revision, printed = event.revision, True
            _print_event(ctx, event)
            remaining = None if remaining is None else remaining - 1
        if interval is not None and time.monotonic() - last_states >= interval:
            states = watcher.take_agent_states()
            if states is not None:
                last_states = time.monotonic()
                _print_states(ctx, states)


def _print_event(ctx: Context, event: MissionEvent) -> None:
    line = json.dumps(event_to_json(event)) if ctx.json else format_event(event)
    print(line, file=ctx.out, flush=True)


def _print_states(ctx: Context, states: dict[str, AgentStatus]) -> None:
    for agent, status in states.items():
        if ctx.json:
            line = json.dumps({"agent": agent, "state": agent_status_to_json(status)})
        else:
            line = f"{'':6} {'STATE':<17} {agent:<18} {format_agent_status(status)}"
        print(line, file=ctx.out, flush=True)
