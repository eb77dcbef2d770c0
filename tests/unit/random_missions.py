"""Random, valid mission content of any size for round-trip tests (files and snapshots).

Used by ``test_mission_text.py`` and ``tests/ros/test_packing.py``. Every skill of the
unit library (every parameter type, marker bindings), every status a file can hold
(finished, failed and retried or skipped, synchronized, removing, uploading, blueprint),
barriers and every marker type; text from an alphabet of what trips YAML and JSON up
(line breaks YAML folds, quotes, escapes, emoji, comment and flow indicators) and numbers
JSON and YAML write differently (exponents, -0.0, the smallest float). Brackets come in
pairs: the YAML reader refuses a document whose brackets, counted even inside text, nest
deeper than 100 (it cannot tell them apart before parsing).
"""

from __future__ import annotations

import random
from dataclasses import replace
from typing import Any

from rosmc_server.core import (
    Barrier,
    Library,
    MarkerType,
    MissionContent,
    Pose,
    Resolution,
    SkillInstance,
    SkillStatus,
    TaskMarker,
    Transfer,
)
from rosmc_server.core.rules.markers import check_marker

S = SkillStatus
# Text any parameter string may hold.
TRICKY = [
    "a", "Z", " ", "é", "ü", "😀", "中", '"', "'", "\\", "#", ": ", "- {}", "[,]", ",",
    "\n", "\t", "\r", "\x85", "\u2028", "\u2029", "\ufeff", "\x7f", "\x1b", "\x00",
    "e-5", "1e-05", "null", "~", "yes", "&a", "*a", "!!python/object", "%", "@", "`",
]  # fmt: skip
# Text a label or status text may hold: one printable line (no Cc/Cf characters).
LINE = ["a", "Z", " ", "é", "😀", '"', "'", "\\", "#", ": ", "- {}", "\u2028", "\xa0",
        "e-5", "1e+05", "null", "yes"]  # fmt: skip
NUMBERS = [0.0, -0.0, 1.0, 0.5, -2.25, 1e-05, 1.5e-07, 1e16, 1e300, 5e-324, 123456789.125]


PLAIN = ["a", "b", "Z", " ", "-", "_", "0", "7", "é", "ü", "😀"]


def text(rng: random.Random, alphabet: list[str], most: int = 8) -> str:
    """Random text, a piece in 20 from ``alphabet``, the rest plain."""
    return "".join(
        rng.choice(alphabet if rng.random() < 0.05 else PLAIN) for _ in range(rng.randint(0, most))
    )


def line(rng: random.Random) -> str:
    """A label-like line: printable, not empty after stripping."""
    return "x" + text(rng, LINE) + "y"


def number(rng: random.Random) -> float:
    """A float, often one that JSON and YAML write differently."""
    return rng.choice(NUMBERS) if rng.random() < 0.05 else round(rng.uniform(-1e3, 1e3), 6)


def json_data(rng: random.Random, depth: int = 0) -> Any:
    """Random JSON-compatible data (what LIST and DICT parameters hold)."""
    kind = rng.randrange(8 if depth < 3 else 5)
    if kind == 0:
        return None
    if kind == 1:
        return rng.random() < 0.5
    if kind == 2:
        return rng.choice([0, -1, 7, 2**40, -(2**62)])
    if kind == 3:
        return number(rng)
    if kind == 4:
        return text(rng, TRICKY)
    if kind in (5, 6):
        return {text(rng, TRICKY, 4): json_data(rng, depth + 1) for _ in range(rng.randint(0, 3))}
    return [json_data(rng, depth + 1) for _ in range(rng.randint(0, 3))]


def markers() -> dict[str, TaskMarker]:
    """A point, a posed goal and an area."""
    corners = (Pose(0, 0), Pose(12.5, 0), Pose(0, 4.5))
    found = [
        TaskMarker("goal é", MarkerType.POSE, Pose(-7.25, 2.0, yaw=0.3)),
        TaskMarker("spot", MarkerType.POSITION, Pose(3.0, 8.0)),
        TaskMarker("field #1", MarkerType.AREA, Pose(1.0, 1.5), corners),
    ]
    return {m.name: m for m in map(check_marker, found)}  # an area's pose is its centroid


def params(rng: random.Random, skill: str, found: dict[str, TaskMarker]) -> tuple[Any, Any]:
    """Valid parameter values and bindings of one skill of the unit library."""
    if skill == "move":
        bound = rng.random() < 0.3
        target = found["goal é"].pose if bound else Pose(number(rng), number(rng), yaw=0.25)
        speed = rng.choice([0.1, 2.0, 1.0, round(rng.uniform(0.1, 2.0), 9)])
        return {"target": target, "speed": speed}, ({"target": "goal é"} if bound else {})
    if skill == "scan":
        area = found["field #1"].value_for(True)
        point = Pose(found["spot"].pose.x, found["spot"].pose.y)
        values = {"area": area, "point": point, "mode": rng.choice(["fast", "slow"])}
        values["passes"] = rng.randint(1, 5)
        return values, {"area": "field #1", "point": "spot"}
    if skill == "wait":
        options = {text(rng, TRICKY, 4): json_data(rng) for _ in range(rng.randint(0, 3))}
        if rng.random() < 0.001:
            options["k" * 1100] = 1  # a key too long for a YAML flow mapping
        values = {"seconds": rng.choice([0, 5, 2**40]), "verbose": rng.random() < 0.5}
        values |= {"note": text(rng, TRICKY), "options": options}
        return values, {}
    return {}, {}


def task(rng: random.Random, agent: str, count: int, found: dict[str, TaskMarker]) -> list[Any]:
    """A task as a robot leaves it: done, failed (retried or skipped), synced, blueprint."""
    skills: list[SkillInstance] = []
    for index in range(count):
        name = rng.choice(["move", "scan", "wait", "noop"])
        values, bindings = params(rng, name, found)
        skills.append(
            SkillInstance(
                id=f"{agent}-{index:05d}",
                agent=agent,
                skill=name,
                label=line(rng) if rng.random() < 0.7 else name,
                params=values,
                bindings=bindings,
                timeout=rng.choice([0.0, 0.0, 12.5, 3600.0, 1e-05 if rng.random() < 0.1 else 1.0]),
                max_retries=rng.choice([0, 0, 2]),
            )
        )
    done, synced, uploading = sorted(rng.sample(range(count + 1), 3))
    for index in range(count):
        skills[index] = with_status(rng, skills[index], index, done, synced, uploading)
    return skills


def with_status(
    rng: random.Random, skill: SkillInstance, index: int, done: int, synced: int, uploading: int
) -> SkillInstance:
    """The skill in the section its index falls in."""
    started = 1732435200.0 + index + rng.choice([0.0, 0.125, 0.333333])
    if index < done:
        if rng.random() < 0.2:
            resolution = rng.choice([Resolution.RETRIED, Resolution.SKIPPED])
            failed = replace(skill, status=S.FAILURE, resolution=resolution, attempt=2)
            return replace(failed, status_text=line(rng), started=started, finished=started + 1.5)
        finished = started + rng.choice([1.0, 2.5e-3])
        done_skill = replace(skill, status=S.SUCCESS, status_text=line(rng))
        return replace(done_skill, started=started, finished=finished)
    if index < synced:
        transfer = Transfer.REMOVING if rng.random() < 0.2 else Transfer.NONE
        return replace(skill, status=S.IDLE_SYNCHRONIZED, transfer=transfer)
    if index < uploading:
        return replace(skill, transfer=Transfer.UPLOADING)
    return skill


def random_content(library: Library, skills: int, seed: int = 12) -> MissionContent:
    """A valid mission of about ``skills`` skills over the library's dynamic agents."""
    rng = random.Random(seed)
    found = markers()
    agents = library.dynamic_agents
    tasks = {agent: task(rng, agent, skills // len(agents), found) for agent in agents}
    blueprint = {a: [s.id for s in t if s.status is S.IDLE] for a, t in tasks.items()}
    barriers: dict[str, Barrier] = {}
    first, second = agents[0], agents[1]
    for k in range(min(len(blueprint[first]), len(blueprint[second]), 50)):
        members = (blueprint[first][k], blueprint[second][k])  # same order: no deadlock
        barriers[f"barrier-{k}"] = Barrier(f"barrier-{k}", members)
    return MissionContent(library.name, tasks, barriers, found)
