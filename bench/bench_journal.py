"""Benchmark of the MCAP mission journal; prints one JSON object.

Measures append latency (p50/p95, with and without fsync, chunked and bare
layouts), bytes per small event, bytes and time per snapshot of a 20-agent x
500-skill mission, recovery time of a 10,000-event journal killed before
closing, what a damaged 12,000-revision journal still recovers (one byte flipped
at half, and 0.01 % of its bytes), and the memory the writer keeps as a journal
grows (tracemalloc over 100,000 changes), and what part files cost the writer (``--only
parts``, :mod:`_journal_parts`). Run from the repository root with the messages built::

    source build/devel/setup.bash
    python bench/bench_journal.py [--dir DIR] [--events N] [--changes N] [--only memory|parts]

``--dir`` should be on the disk the server journals to: fsync figures depend on it.
"""

import argparse
import gc
import json
import logging
import random
import statistics
import sys
import tempfile
import time
import tracemalloc
from collections.abc import Callable, Sequence
from functools import partial
from io import BytesIO
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
sys.path.insert(0, str(Path(__file__).resolve().parent))

import rosmc.msg as wire

from rosmc_server.recording import (
    JournalOptions,
    JournalWriter,
    latest_state,
    read_journal,
)


def small_event(revision: int) -> Any:
    """An add-skill event of the usual size: one skill with four parameters."""
    params = [
        wire.ParameterValue(name="goal", type=wire.ParameterValue.POSE, marker="rss_3"),
        wire.ParameterValue(name="speed", type=wire.ParameterValue.FLOAT, float_value=0.8),
        wire.ParameterValue(name="mode", type=wire.ParameterValue.STRING, string_value="fast"),
        wire.ParameterValue(name="retries", type=wire.ParameterValue.INT, int_value=2),
    ]
    skill = wire.Skill(
        id=f"sk-{revision:06d}",
        agent="science_rover",
        skill="move_to",
        label="move to RSS 3",
        parameters=params,
        attempt=1,
        timeout=120.0,
    )
    return wire.MissionEvent(
        revision=revision,
        kind=wire.MissionEvent.SKILL_ADDED,
        agent="science_rover",
        summary=f"added move_to to science_rover at 12 (revision {revision})",
        put_skills=[wire.PlacedSkill(index=12, skill=skill)],
    )


def big_mission(revision: int, agents: int = 20, skills: int = 500) -> Any:
    """A mission of ``agents`` x ``skills`` skills, each with four parameters."""
    tasks = []
    for a in range(agents):
        agent = f"robot_{a:02d}"
        task = []
        for s in range(skills):
            params = [
                wire.ParameterValue(
                    name="goal",
                    type=wire.ParameterValue.POSE,
                    marker=f"poi_{s % 40}",
                    pose_value=wire.Pose6D(x=s * 0.5, y=a * 1.5, yaw=0.1 * s),
                ),
                wire.ParameterValue(name="speed", type=wire.ParameterValue.FLOAT, float_value=0.5),
                wire.ParameterValue(
                    name="note", type=wire.ParameterValue.STRING, string_value=f"leg {s}"
                ),
                wire.ParameterValue(name="tries", type=wire.ParameterValue.INT, int_value=3),
            ]
            task.append(
                wire.Skill(
                    id=f"{agent}-{s:04d}",
                    agent=agent,
                    skill="move_to",
                    label=f"move to poi {s}",
                    parameters=params,
                    status=wire.SkillStatus(value=s % 3),
                    attempt=1,
                )
            )
        tasks.append(wire.AgentTask(agent=agent, skills=task))
    return wire.Mission(revision=revision, library="mars_sample_collection", tasks=tasks)


def percentiles(samples: Sequence[float]) -> dict[str, float]:
    """p50 / p95 / max of latencies given in seconds, in microseconds."""
    ordered = sorted(samples)
    return {
        "p50_us": round(statistics.median(ordered) * 1e6, 1),
        "p95_us": round(ordered[int(len(ordered) * 0.95)] * 1e6, 1),
        "max_us": round(ordered[-1] * 1e6, 1),
    }


def timed(action: Callable[[], Any]) -> float:
    """Seconds one call of ``action`` takes."""
    start = time.perf_counter()
    action()
    return time.perf_counter() - start


def bench_appends(directory: Path, chunked: bool, fsync: bool, count: int) -> dict[str, Any]:
    """Latency and size of appending ``count`` small events."""
    path = (
        directory / f"append_{'chunked' if chunked else 'bare'}_{'fsync' if fsync else 'os'}.mcap"
    )
    options = JournalOptions(chunked=chunked, fsync=fsync, snapshot_every=10**9)
    writer = JournalWriter.create(path, wire.Mission(), 0, options)
    for rev in range(1, 51):  # warm up: first calls pay for lazy imports and caches
        writer.append_event(small_event(rev), time.time_ns())
    events = [small_event(rev) for rev in range(51, count + 51)]
    start_offset = writer.offset
    latencies = [timed(partial(writer.append_event, e, time.time_ns())) for e in events]
    data_end = writer.offset
    writer.close()
    return {
        **percentiles(latencies),
        "bytes_per_event": round((data_end - start_offset) / count, 1),
        "summary_bytes_per_event": round((path.stat().st_size - data_end) / (count + 50), 1),
        "event_payload_bytes": len(_serialized(events[0])),
    }


def bench_all_appends(directory: Path, count: int) -> dict[str, Any]:
    """Append latency of both layouts with fsync (the default) and without (``fsync=False``)."""
    figures: dict[str, Any] = {}
    for chunked in (True, False):
        layout = "chunked" if chunked else "bare"
        figures[layout] = bench_appends(directory, chunked, False, count)
        figures[f"{layout}_fsync"] = bench_appends(directory, chunked, True, max(count // 10, 50))
    return figures


def bench_snapshot(directory: Path) -> dict[str, Any]:
    """Size and cost of a 20 x 500 snapshot, compressed (default) and not."""
    mission = big_mission(1)
    build = timed(lambda: big_mission(1))
    result: dict[str, Any] = {"skills": 20 * 500, "build_ms": round(build * 1e3, 1)}
    for name, compress_from in (("zstd", JournalOptions().compress_from), ("plain", 0)):
        path = directory / f"snapshot_{name}.mcap"
        writer = JournalWriter.create(
            path, wire.Mission(), 0, JournalOptions(compress_from=compress_from)
        )
        before = writer.offset
        seconds = timed(partial(writer.append_snapshot, mission, time.time_ns()))
        result[f"{name}_bytes"] = writer.offset - before
        result[f"{name}_append_ms"] = round(seconds * 1e3, 1)
        writer.close()
        result[f"{name}_read_ms"] = round(timed(partial(read_journal, path)) * 1e3, 1)
    buffer_size = len(_serialized(mission))
    result["serialized_bytes"] = buffer_size
    return result


def bench_recovery(directory: Path, events: int, chunked: bool) -> dict[str, Any]:
    """Recovery of a journal of ``events`` events (snapshot every 500) that was never closed."""
    path = directory / f"recover_{'chunked' if chunked else 'bare'}.mcap"
    options = JournalOptions(chunked=chunked, snapshot_every=500)
    mission = big_mission(0, agents=4, skills=50)
    writer = JournalWriter.create(path, mission, 0, options)
    for rev in range(1, events + 1):
        writer.append_event(small_event(rev), rev)
        if writer.snapshot_due:
            mission.revision = rev
            writer.append_snapshot(mission, rev)
    writer.abandon()
    with path.open("ab") as file:
        file.write(b"\x05\x40\x00")  # a record cut short, as kill -9 can leave
    read_s = timed(lambda: read_journal(path))
    state_s = timed(lambda: latest_state(read_journal(path)))
    resume_s = timed(lambda: JournalWriter.resume(path, options).close())
    return {
        "events": events,
        "file_bytes": path.stat().st_size,
        "read_journal_ms": round(read_s * 1e3, 1),
        "read_and_latest_state_ms": round(state_s * 1e3, 1),
        "resume_and_close_ms": round(resume_s * 1e3, 1),
    }


def bench_memory(directory: Path, changes: int, traced: int = 5_000) -> dict[str, Any]:
    """What the writer keeps in memory while a journal grows by ``changes`` events.

    A snapshot of a 4 x 50 mission every 500 events, as the server writes them. The
    process's resident memory is read at ten points along the way (a bound shows as a
    figure that stops growing); the memory each change leaves behind is measured exactly
    (tracemalloc, which slows appends 30x) over the first ``traced`` changes.
    """
    path = directory / "memory.mcap"
    mission = big_mission(0, agents=4, skills=50)
    writer = JournalWriter.create(path, mission, 0, JournalOptions())
    step = max(changes // 10, 1)
    rss: dict[str, int] = {}
    gc.collect()
    base = _rss_kib()
    for rev in range(1, changes + 1):
        if rev == 1:
            tracemalloc.start()
        writer.append_event(small_event(rev), rev)
        if writer.snapshot_due:
            mission.revision = rev
            writer.append_snapshot(mission, rev)
        if rev == traced:
            gc.collect()
            per_change = tracemalloc.get_traced_memory()[0] / traced
            tracemalloc.stop()
        if rev % step == 0:
            gc.collect()
            rss[str(rev)] = _rss_kib() - base
    writer.close()
    files = [path, *directory.glob("memory.part*.mcap")]
    return {
        "changes": changes,
        "files": len(files),
        "journal_mib": round(sum(f.stat().st_size for f in files) / 2**20, 1),
        "retained_bytes_per_change": round(per_change, 1),
        "rss_growth_kib": rss,
        "rss_growth_max_kib": max(rss.values()),
        "rss_growth_last_half_kib": rss[str(changes)]
        - rss[str(changes // 2 - (changes // 2) % step)],
    }


def bench_damage(directory: Path, events: int = 12_000) -> dict[str, Any]:
    """What a journal of ``events`` events (snapshot every 500) recovers when damaged."""
    path = directory / "damage.mcap"
    mission = big_mission(0, agents=4, skills=50)
    writer = JournalWriter.create(path, mission, 0, JournalOptions())
    for rev in range(1, events + 1):
        writer.append_event(small_event(rev), rev)
        if writer.snapshot_due:
            mission.revision = rev
            writer.append_snapshot(mission, rev)
    writer.abandon()
    clean = path.read_bytes()
    rng = random.Random(20261124)
    after_preamble = range(len(clean) // 100, len(clean))
    cases = {
        "one_byte_at_half": [len(clean) // 2],
        "bytes_0.01_percent": rng.sample(after_preamble, len(clean) // 10_000),
    }
    figures: dict[str, Any] = {"events": events}
    for name, offsets in cases.items():
        damaged = bytearray(clean)
        for offset in offsets:
            damaged[offset] ^= 0x5A
        path.write_bytes(bytes(damaged))
        began = time.perf_counter()
        result = read_journal(path)
        state = latest_state(result)
        figures[name] = {
            "flipped": len(offsets),
            "read_ms": round((time.perf_counter() - began) * 1e3, 1),
            "events_kept": sum(r.topic == "/rosmc/mission_events" for r in result.records),
            "resumed_at": state.revision,
            "next_revision": state.next_revision,
            "revisions_lost": sum(gap.revisions.count for gap in state.gaps),
        }
    return figures


def _rss_kib() -> int:
    """This process's resident set size (KiB)."""
    for line in Path("/proc/self/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1])
    raise RuntimeError("no VmRSS in /proc/self/status")


def _serialized(message: Any) -> bytes:
    buffer = BytesIO()
    message.serialize(buffer)
    return buffer.getvalue()


def main(argv: Sequence[str] | None = None) -> int:
    """Run every measurement and print the figures as JSON."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--dir", type=Path, default=None, help="where to write (default: a temp dir)"
    )
    parser.add_argument("--events", type=int, default=10_000, help="events in the recovery journal")
    parser.add_argument("--appends", type=int, default=2_000, help="appends per latency run")
    parser.add_argument("--changes", type=int, default=100_000, help="changes of the memory run")
    parser.add_argument(
        "--only", choices=["memory", "append", "parts"], help="run only this measurement"
    )
    args = parser.parse_args(argv)
    logging.basicConfig(level=logging.ERROR)  # recovery warnings are expected here
    with tempfile.TemporaryDirectory(dir=args.dir) as tmp:
        directory = Path(tmp)
        if args.only == "memory":
            print(json.dumps({"memory": bench_memory(directory, args.changes)}, indent=2))
            return 0
        if args.only == "parts":
            from _journal_parts import bench_parts

            print(json.dumps({"parts": bench_parts(directory)}, indent=2))
            return 0
        if args.only == "append":
            print(json.dumps({"append": bench_all_appends(directory, args.appends)}, indent=2))
            return 0
        # First: the resident memory it reads must not include the other runs' heap.
        figures: dict[str, Any] = {"memory": bench_memory(directory, args.changes)}
        figures.update(append=bench_all_appends(directory, args.appends), recovery={})
        for chunked in (True, False):
            layout = "chunked" if chunked else "bare"
            figures["recovery"][layout] = bench_recovery(directory, args.events, chunked)
        figures["snapshot_20x500"] = bench_snapshot(directory)
        figures["damage"] = bench_damage(directory)
        figures["filesystem_dir"] = str(directory.parent)
    print(json.dumps(figures, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
