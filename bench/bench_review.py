"""Benchmark of reading a big journal back: resume, ``rosmc at``, ``rosmc info``, replay.

Writes journals of a 2 x 5,000-skill mission with 6,000, 12,000, 24,000 and 48,000
operator changes through the real JournalWriter with the server's options (a snapshot
every 500 events, a part file every 4,000 changes or 4 MiB; events packed by
``packed_event``, snapshots by ``SnapshotPacker``), each once closed and once left as a
crash leaves it (``abandon()`` and a torn record in its last part).
Then measures, each in a process of its own (wall time and peak RSS of that process):

* ``resume``: what the server's resume does (``JournalWriter.resume`` on a copy of every part,
  ``latest_state``, the mission rebuilt from the snapshot and the events after it);
  ``held_mib`` is the process's RSS once only the resumed mission is left (the
  server's live memory for it, imports included);
* ``at``: ``rosmc at FILE rN`` at the middle revision;
* ``info``: ``rosmc info FILE``;
* ``replay``: opening a replay as ``rosmc replay`` does (read, history, replayer, the
  first state's snapshot message), then ``seeks`` seeks to random positions (each
  the revision there and its snapshot message, what the replayer publishes).

Prints one JSON object, with the machine's load average before and after. Run from the
repository root after ``source env.sh``::

    python bench/bench_review.py [--edits 6000,12000,24000,48000] [--dir DIR] [--keep]

``--dir DIR --keep`` writes the journals into DIR once and reuses them on later runs.
"""

from __future__ import annotations

import argparse
import contextlib
import gc
import io
import json
import logging
import os
import random
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))
sys.path.insert(0, str(REPO / "bench"))

T0 = 1_770_000_000_000_000_000  # log time (ns) of the first record
STEP = 250_000_000  # ns between two changes


def write_journal(path: Path, edits: int, closed: bool, agents: int, skills: int) -> None:
    """A journal of ``edits`` changes of an ``agents`` x ``skills`` mission."""
    import yaml
    from _missions import library_yaml, mission_yaml

    from rosmc_server.conversions.event_packing import packed_event
    from rosmc_server.conversions.packing import SnapshotPacker
    from rosmc_server.core import Mission
    from rosmc_server.core.files.persistence import parse_mission
    from rosmc_server.core.skills.library import library_from_dict
    from rosmc_server.recording import JournalOptions, JournalWriter

    library = library_from_dict(yaml.safe_load(library_yaml(agents)))
    content, _ = parse_mission(mission_yaml(agents, skills), library, "bench")
    now = [T0 / 1e9]
    mission = Mission(library, content, 0, clock=lambda: now[0])
    packer = SnapshotPacker()
    options = JournalOptions(fsync=False, snapshot_every=500)
    writer = JournalWriter.create(path, packer.pack(content, 0, now[0]), T0, options)
    rng = random.Random(edits * 7 + closed)
    state = mission.state
    for number in range(1, edits + 1):
        log_time = T0 + number * STEP
        now[0] = log_time / 1e9
        agent = f"robot_{rng.randrange(agents):02d}"
        task = state.task(agent)
        roll = rng.random()
        if roll < 0.05:
            event = mission.add_skill(
                agent, "wait", {"seconds": 2.0}, index=rng.randrange(len(task))
            )
        elif roll < 0.08 and len(task) > 10:
            event = mission.delete_skills([task[rng.randrange(len(task))].id])
        else:
            skill = task[rng.randrange(len(task))]
            if skill.skill == "move":
                params: dict[str, object] = {"speed": round(rng.uniform(0.1, 1.9), 2)}
            elif skill.skill == "inspect":
                params = {"radius": round(rng.uniform(0.6, 9.0), 2), "tries": rng.randint(1, 5)}
            else:
                params = {"seconds": round(rng.uniform(1.0, 9.0), 1)}
            event = mission.edit_skill(skill.id, params, label=f"edit {number}")
        msg = packed_event(event, lambda skill_id: state.locate(skill_id)[0], "bench")
        writer.append_event(msg, log_time)
        if writer.snapshot_due:
            writer.append_snapshot(packer.pack(state.content(), mission.revision, now[0]), log_time)
    if closed:
        writer.close()
    else:
        writer.abandon()
        with writer.part_path.open("ab") as file:
            file.write(b"\x06\x40\x00")  # a record cut short, as kill -9 can leave


# -- the measurements, each run in a process of its own ------------------------------------
def _peak_mib() -> float:
    return round(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024, 1)


def _rss_mib() -> float:
    for line in Path("/proc/self/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return round(int(line.split()[1]) / 1024, 1)
    return 0.0


def measure_resume(path: Path) -> dict[str, Any]:
    """The server's resume: reopen a copy, pick the latest state, rebuild the mission."""
    from rosmc_server.conversions import event_from_msg, mission_from_msg
    from rosmc_server.core import Mission
    from rosmc_server.core.skills.library import Library  # noqa: F401  (import cost before timing)
    from rosmc_server.recording import JournalOptions, JournalWriter, latest_state
    from rosmc_server.recording._mcap.files import journal_parts, part_path

    copy = path.with_name(f"resume-{os.getpid()}.mcap")
    for number, part in journal_parts(path)[1]:
        shutil.copyfile(part, part_path(copy, number))
    try:
        gc.collect()
        base = _rss_mib()
        began = time.perf_counter()
        writer = JournalWriter.resume(copy, JournalOptions(fsync=False))
        assert writer.recovered is not None
        latest = latest_state(writer.recovered)
        read = time.perf_counter() - began
        content, revision = mission_from_msg(latest.snapshot)
        mission = Mission(_library(), content, revision)
        for event in latest.events:
            mission.replay(event_from_msg(event))
        wall = time.perf_counter() - began
        writer.abandon()
        del writer, latest, content
        gc.collect()
        return {
            "wall_s": round(wall, 3),
            "read_and_latest_state_s": round(read, 3),
            "revision": mission.revision,
            "imports_mib": base,
            "held_mib": _rss_mib(),
        }
    finally:
        for leftover in copy.parent.glob(f"{copy.stem}*"):
            leftover.unlink()


def _library() -> Any:
    import yaml
    from _missions import library_yaml

    from rosmc_server.core.skills.library import library_from_dict

    return library_from_dict(yaml.safe_load(library_yaml(2)))


def measure_cli(argv: list[str]) -> dict[str, Any]:
    """One ``rosmc`` command, its output thrown away."""
    from rosmc_server.cli.main import main as rosmc

    began = time.perf_counter()
    with contextlib.redirect_stdout(io.StringIO()) as out:
        code = rosmc(argv)
    wall = time.perf_counter() - began
    return {"wall_s": round(wall, 3), "exit": code, "output_lines": out.getvalue().count("\n")}


def measure_replay(path: Path, seeks: int) -> dict[str, Any]:
    """Open a replay as ``rosmc replay`` does, then seek to random positions."""
    from rosmc_server.recording import read_journal
    from rosmc_server.recording.history import MissionHistory
    from rosmc_server.ros.replayer import RecordingReplayer, ReplayConfig

    began = time.perf_counter()
    result = read_journal(path)
    history = MissionHistory(result)
    player = RecordingReplayer(history, result.records, ReplayConfig(paused=True))
    first = player.mission_at(0.0)
    opened = time.perf_counter() - began
    rng = random.Random(5)
    times = []
    revisions = []
    for _ in range(seeks):
        position = rng.uniform(0.0, history.duration)
        start = time.perf_counter()
        msg = player.mission_at(position)
        times.append(time.perf_counter() - start)
        revisions.append(int(msg.revision))
    return {
        "open_s": round(opened, 3),
        "first_revision": int(first.revision),
        "seek_p50_ms": round(statistics.median(times) * 1e3, 1),
        "seek_max_ms": round(max(times) * 1e3, 1),
        "seeks": seeks,
    }


def child(kind: str, path: Path, extra: str) -> None:
    """Run one measurement in this process and print its figures (with the peak RSS)."""
    logging.basicConfig(level=logging.ERROR)  # a crash-left journal warns; expected here
    if kind == "write":
        edits, closed, agents, skills = (int(value) for value in extra.split(","))
        write_journal(path, edits, bool(closed), agents, skills)
        return
    if kind == "resume":
        figures = measure_resume(path)
    elif kind == "at":
        figures = measure_cli(["at", str(path), extra])
    elif kind == "info":
        figures = measure_cli(["info", str(path)])
    else:
        figures = measure_replay(path, int(extra))
    figures["peak_rss_mib"] = _peak_mib()
    print(json.dumps(figures))


def run_child(kind: str, path: Path, extra: str = "") -> dict[str, Any]:
    """Figures of one measurement, run in a fresh process."""
    done = subprocess.run(
        [sys.executable, __file__, "--child", kind, str(path), extra],
        capture_output=True,
        text=True,
        check=False,
    )
    if done.returncode != 0:
        return {"failed": done.returncode, "stderr": done.stderr[-2000:]}
    return dict(json.loads(done.stdout.strip().splitlines()[-1]))


def main(argv: Sequence[str] | None = None) -> int:
    """Write the journals (or reuse them), measure each path and print the figures."""
    from rosmc_server.recording._mcap.files import journal_parts

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--edits", default="6000,12000,24000,48000", help="changes per journal, by commas"
    )
    parser.add_argument("--agents", type=int, default=2)
    parser.add_argument("--skills", type=int, default=5000, help="skills per agent")
    parser.add_argument("--seeks", type=int, default=10, help="seeks per replay run")
    parser.add_argument("--dir", type=Path, default=None, help="where the journals go")
    parser.add_argument("--keep", action="store_true", help="keep (and reuse) the journals")
    parser.add_argument("--only", default="", help="resume,at,info,replay (default: all)")
    parser.add_argument("--child", nargs=3, help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.child:
        child(args.child[0], Path(args.child[1]), args.child[2])
        return 0
    kinds = [k for k in args.only.split(",") if k] or ["resume", "at", "info", "replay"]
    directory = args.dir or Path(tempfile.mkdtemp(prefix="bench_review_"))
    directory.mkdir(parents=True, exist_ok=True)
    figures: dict[str, Any] = {"load_average_before": list(os.getloadavg())}
    began = time.perf_counter()
    try:
        for edits in (int(e) for e in args.edits.split(",")):
            for closed in (True, False):
                ending = "closed" if closed else "crashed"
                name = f"review_{args.agents}x{args.skills}_{edits}_{ending}"
                path = directory / f"{name}.mcap"
                if not path.exists():  # in a process of its own: a child forked from a
                    # big parent would report the parent's RSS as its own peak
                    written = time.perf_counter()
                    how = f"{edits},{int(closed)},{args.agents},{args.skills}"
                    subprocess.run(
                        [sys.executable, __file__, "--child", "write", str(path), how], check=True
                    )
                    figures.setdefault("write_s", {})[name] = round(
                        time.perf_counter() - written, 1
                    )
                files = [part for _, part in journal_parts(path)[1]]
                entry: dict[str, Any] = {
                    "bytes": sum(part.stat().st_size for part in files),
                    "parts": len(files),
                }
                for kind in kinds:
                    extra = {"at": f"r{edits // 2}", "replay": str(args.seeks)}.get(kind, "")
                    entry[kind] = run_child(kind, path, extra)
                    entry[kind]["load_average"] = round(os.getloadavg()[0], 2)
                figures[name] = entry
    finally:
        if not args.keep:
            shutil.rmtree(directory, ignore_errors=True)
    figures["load_average_after"] = list(os.getloadavg())
    figures["seconds"] = round(time.perf_counter() - began, 1)
    print(json.dumps(figures, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
