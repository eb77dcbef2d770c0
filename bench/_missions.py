"""Generated libraries and mission documents for the mission-server benchmarks.

A library of dynamic agents of one model with typical skills, and mission documents of
any size over it (optionally with barriers across every task), named so that a benchmark
knows every skill's id without asking the server.
"""

from __future__ import annotations

import yaml


def agent_name(index: int) -> str:
    """The name of the benchmark's agent number ``index``."""
    return f"robot_{index:02d}"


def skill_id(agent: int, number: int) -> str:
    """The id :func:`mission_yaml` gives skill ``number`` of agent ``agent``."""
    return f"{agent_name(agent)}-s{number:05d}"


def library_yaml(agents: int) -> str:
    """A library of ``agents`` dynamic agents of one model with typical skills."""
    skills = {
        "move": {
            "duration": 60,
            "parameters": {
                "target": {"type": "pose", "default": {"x": 0.0, "y": 0.0}, "marker": "pose"},
                "speed": {"type": "float", "default": 0.5, "min": 0.05, "max": 2.0},
            },
        },
        "inspect": {
            "duration": 30,
            "parameters": {
                "radius": {"type": "float", "default": 2.0, "min": 0.5, "max": 10.0},
                "mode": {
                    "type": "string",
                    "default": "standard",
                    "choices": ["quick", "standard", "detailed"],
                },
                "tries": {"type": "int", "default": 1, "min": 1, "max": 5},
            },
        },
        "wait": {"duration": 10, "parameters": {"seconds": {"type": "float", "default": 5.0}}},
    }
    return yaml.safe_dump(
        {
            "rosmc_library": 1,
            "name": f"bench_{agents}",
            "models": {"robot": {"skills": skills}},
            "agents": {agent_name(i): {"kind": "dynamic", "model": "robot"} for i in range(agents)},
        },
        sort_keys=False,
    )


def barrier_positions(skills: int, barriers: int) -> list[int]:
    """Skill numbers, evenly spread over a task of ``skills``, that :func:`mission_yaml`
    joins in barriers across all agents."""
    step = skills // barriers if barriers else 0
    return [number * step for number in range(barriers)] if step else []


def mission_yaml(agents: int, skills: int, barriers: int = 0) -> str:
    """A mission document: ``skills`` blueprint skills per agent, one task marker and
    ``barriers`` barriers, each over the skills of one :func:`barrier_positions` number."""
    kinds = ["move", "inspect", "wait"]
    params = {
        "move": {
            "target": {"x": 1.0, "y": 2.0, "z": 0.0, "roll": 0.0, "pitch": 0.0, "yaw": 0.5},
            "speed": 0.8,
        },
        "inspect": {"radius": 3.0, "mode": "quick", "tries": 2},
        "wait": {"seconds": 5.0},
    }
    tasks = {}
    for a in range(agents):
        tasks[agent_name(a)] = [
            {
                "id": skill_id(a, k),
                "skill": kinds[k % 3],
                "label": f"step {k}",
                "params": params[kinds[k % 3]],
                "status": "IDLE",
            }
            for k in range(skills)
        ]
    groups = [
        {"id": f"barrier-{k:05d}", "skills": [skill_id(a, k) for a in range(agents)]}
        for k in barrier_positions(skills, barriers)
    ]
    marker = {"name": "Site", "type": "POSE", "pose": {"x": 3.0, "y": 4.0}}
    return yaml.safe_dump(
        {
            "rosmc_mission": 1,
            "library": f"bench_{agents}",
            "revision": 0,
            "tasks": tasks,
            "barriers": groups,
            "markers": [marker],
        },
        sort_keys=False,
    )
