"""What part files cost the writer: ``bench_journal.py --only parts``.

The server's journal (:class:`MissionJournal`, its revision mark included) takes
``changes`` label edits of a 2 x ``skills`` mission with fsync, a snapshot whenever one
is due, once with the default part files (a new file every 4,000 changes or 4 MiB) and
once as one file (parts of 32 MiB and no count). Per run: the time of each change's
record (p50/p95/max), of each due snapshot (p50/max) and of the snapshots that started a
part, the whole run's seconds and the files written. With more than one file, every
change also rewrites the revision mark in the first file's head, and a lease renewal
(every 250 changes) syncs it.
"""

from __future__ import annotations

import statistics
import time
from pathlib import Path
from typing import Any

import yaml
from _missions import library_yaml, mission_yaml

from rosmc_server.conversions import mission_to_msg
from rosmc_server.core.files.persistence import parse_mission
from rosmc_server.core.skills.library import library_from_dict
from rosmc_server.recording import JournalOptions
from rosmc_server.recording.mission_journal import MissionJournal

ONE_FILE = JournalOptions(part_bytes=32 * 1024 * 1024, part_changes=10**12)


def bench_parts(directory: Path, changes: int = 12_000, skills: int = 500) -> dict[str, Any]:
    """The writer's cost with part files and as one file (see module docstring)."""
    return {
        "changes": changes,
        "skills": 2 * skills,
        "parts": _run(directory / "parts", JournalOptions(), changes, skills),
        "one_file": _run(directory / "one_file", ONE_FILE, changes, skills),
    }


def _run(directory: Path, options: JournalOptions, changes: int, skills: int) -> dict[str, Any]:
    from rosmc_server.core import Mission

    directory.mkdir()
    library = library_from_dict(yaml.safe_load(library_yaml(2)))
    content, _ = parse_mission(mission_yaml(2, skills), library, "bench")
    mission = Mission(library, content, 0)
    journal = MissionJournal.create(directory / "m.mcap", mission, options)
    writer = journal.writer
    ids = [skill.id for skill in mission.state.task("robot_00")]
    records: list[float] = []
    snapshots: list[float] = []
    rotations: list[float] = []
    began = time.perf_counter()
    for number in range(changes):
        event = mission.edit_skill(ids[number % len(ids)], {}, label=f"edit {number}")
        start = time.perf_counter()
        journal.record(event, mission, _snapshot)  # type: ignore[arg-type]
        records.append(time.perf_counter() - start)
        if writer.snapshot_due:
            part = writer.part_path
            start = time.perf_counter()
            writer.append_due_snapshot(_snapshot(mission), time.time_ns())
            (rotations if writer.part_path != part else snapshots).append(
                time.perf_counter() - start
            )
    seconds = time.perf_counter() - began
    journal.close()
    files = list(directory.glob("m*.mcap"))
    return {
        "files": len(files),
        "mib": round(sum(f.stat().st_size for f in files) / 2**20, 1),
        "seconds": round(seconds, 2),
        "record_ms": _ms(records),
        "snapshot_ms": _ms(snapshots),
        "part_start_ms": _ms(rotations),
    }


def _snapshot(mission: Any) -> Any:
    return mission_to_msg(mission.state.content(), mission.revision, time.time())


def _ms(samples: list[float]) -> dict[str, float]:
    if not samples:
        return {}
    ordered = sorted(samples)
    return {
        "count": len(ordered),
        "p50": round(statistics.median(ordered) * 1e3, 3),
        "p95": round(ordered[int(0.95 * (len(ordered) - 1))] * 1e3, 3),
        "max": round(ordered[-1] * 1e3, 3),
    }
