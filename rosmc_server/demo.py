"""Scripted mission run through the mission core, printing each robot's task.

This is the main job until the simulated team exists: it plans the paper's
sample-return mission, synchronizes part of it, plays the robots' reports,
adapts the plan mid-mission (unsynchronize, edit, re-synchronize) and prints
how every robot's task looks after each phase.
"""

from __future__ import annotations

import argparse
import itertools
import sys
from collections.abc import Sequence
from pathlib import Path

from .core import Mission, MissionEvent, Pose, SkillStatus, TaskMarker, load_library
from .core.skills.params import MarkerType
from .text import format_tasks

LIBRARY = Path(__file__).resolve().parent / "config" / "mars_team.yaml"


def print_tasks(mission: Mission, title: str) -> None:
    """Print every robot's task: synchronized section, a rule, then the blueprint."""
    print("\n" + format_tasks(mission.state, title))


def run(out_events: list[MissionEvent]) -> Mission:
    """Run the scripted mission; every accepted event is appended to ``out_events``."""
    counter = itertools.count(1)
    clock = itertools.count(0, 5)
    mission = Mission(
        load_library(LIBRARY),
        new_id=lambda prefix: f"{prefix}-{next(counter)}",
        clock=lambda: float(next(clock)),
    )

    def do(event: MissionEvent) -> MissionEvent:
        out_events.append(event)
        print(f"  r{event.revision:<3} {event.summary}")
        return event

    def added(event: MissionEvent) -> str:
        return do(event).change.put_skills[0].skill.id

    print("Planning the sample-return mission")
    do(mission.add_marker(TaskMarker("", MarkerType.AREA, Pose(), _square(12.0, 8.0, 6.0))))
    do(mission.add_marker(TaskMarker("RSS A", MarkerType.POSITION, Pose(10.0, 6.0))))
    do(mission.add_marker(TaskMarker("Wi-Fi spot", MarkerType.POSE, Pose(6.0, -3.0))))
    take_off = added(mission.add_skill("drone", "take_off", {"altitude": 8.0}))
    added(mission.add_skill("drone", "fly_over", bindings={"area": "Area 1"}))
    added(mission.add_skill("drone", "return_to_lander"))
    go_sci = added(mission.add_skill("science_rover", "navigate_to", bindings={"target": "RSS A"}))
    ident_sci = added(
        mission.add_skill("science_rover", "identify_stones", bindings={"position": "RSS A"})
    )
    box = added(mission.add_skill("manipulator_rover", "pick_box", {"box": "wifi_box"}))
    place = added(
        mission.add_skill("manipulator_rover", "place_box", bindings={"target": "Wi-Fi spot"})
    )
    added(mission.add_skill("manipulator_rover", "navigate_to", bindings={"target": "RSS A"}))
    ident_man = added(
        mission.add_skill("manipulator_rover", "identify_stones", bindings={"position": "RSS A"})
    )
    added(mission.add_skill("manipulator_rover", "pick_stone", bindings={"position": "RSS A"}))
    added(mission.add_skill("manipulator_rover", "deposit_at_lander"))
    do(mission.add_barrier([ident_sci, ident_man]))
    print_tasks(mission, "Blueprint ready")

    print("\nSynchronizing the first skills and letting the robots work")
    for agent, upto in (("drone", None), ("science_rover", go_sci), ("manipulator_rover", place)):
        uploading = do(mission.synchronize(agent, upto))
        ids = [placed.skill.id for placed in uploading.change.put_skills]
        do(mission.confirm_synchronized(agent, ids))
    for skill_id in (take_off, go_sci, box):
        do(mission.report_status(skill_id, SkillStatus.RUNNING))
        do(mission.report_status(skill_id, SkillStatus.SUCCESS))
    do(mission.report_status(place, SkillStatus.RUNNING))
    print_tasks(mission, "Robots at work")

    print("\nAdapting: the Wi-Fi spot is not traversable; pull it back, move it, re-sync")
    do(mission.stop("manipulator_rover"))
    do(mission.unsynchronize("manipulator_rover", place))
    do(mission.confirm_unsynchronized("manipulator_rover", [place]))
    do(mission.move_marker("Wi-Fi spot", Pose(5.0, -1.0, 0.0, 0.0, 0.0, 1.57)))
    do(mission.synchronize("manipulator_rover"))
    pending = [s.id for s in mission.state.task("manipulator_rover") if s.transfer]
    do(mission.confirm_synchronized("manipulator_rover", pending))
    do(mission.synchronize("science_rover"))
    pending = [s.id for s in mission.state.task("science_rover") if s.transfer]
    do(mission.confirm_synchronized("science_rover", pending))
    print_tasks(mission, "Adapted mission, fully synchronized")
    return mission


def _square(x: float, y: float, size: float) -> tuple[Pose, ...]:
    half = size / 2
    corners = ((-half, -half), (half, -half), (half, half), (-half, half))
    return tuple(Pose(x + dx, y + dy) for dx, dy in corners)


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of ``rosmc_demo``."""
    parser = argparse.ArgumentParser(
        prog="rosmc_demo",
        description="Plan, synchronize and adapt the sample-return mission in the mission "
        "core, printing each robot's task.",
    )
    parser.parse_args([a for a in (argv if argv is not None else sys.argv[1:]) if ":=" not in a])
    events: list[MissionEvent] = []
    mission = run(events)
    print(f"\n{len(events)} accepted changes; final revision {mission.revision}.")
    return 0


if __name__ == "__main__":
    sys.exit(main())
