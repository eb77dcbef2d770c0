"""Benchmark of the mission server's operator services; prints one JSON object.

Starts its own ``rosmaster`` on a free loopback port and, per mission size (agents x
skills per agent), a real ``mission_server`` on a generated library of that many dynamic
agents. The mission is loaded as one document, then each operation is timed from a
client with persistent service proxies: median and p95 latency of add, edit, delete,
reorder, add barrier, marker move, synchronize and get_mission (read into core objects as
the project's client reads it; ``get_mission_genpy``: decoded by genpy); bytes per event, per
snapshot and per journaled change; the server's peak RSS after the load and after each
phase; after them, how long the latched ``/rosmc/mission`` takes to catch up with a burst
of 200 back-to-back adds, and how many snapshots the burst caused. Before the per-change
operations (a load is refused once robots hold synchronized
skills), the whole-mission paths (``whole``), ``--whole-repeats`` times each, p50 and p95
(with a few repeats, the max): get_mission right after a change and again at the same
revision (decoded by genpy, read into core objects, and as raw bytes: the server and
transport alone, with each client-side read timed apart), save to a path on the server
and save returning the document (each right after a change), and loading the mission the
server saved (also as the server's CPU time, which other work on the machine inflates less
than the wall time, and the server's own read/serialize/apply split from its log).
Run from the repository root::

    source env.sh
    python bench/bench_server.py [--sizes 2x10,5x100,20x500] [--samples 300] [--profile]
    python bench/bench_server.py --sizes 2x500,10x500,20x500 --samples 0 --cpu-seconds 30

``--samples 0`` skips the per-change operations. ``--cpu-seconds N`` (15 unless given; 0
skips it) measures, at the largest size, the server's CPU time over N s of 10 changes/s
without and then with a subscriber to the latched ``/rosmc/mission``. ``--profile`` runs
the largest size a second time under cProfile (every server thread) and adds the top
functions by internal time to the output.
"""

from __future__ import annotations

import argparse
import dataclasses
import io
import pstats
import random
import sys
import time
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
sys.path.insert(0, str(Path(__file__).resolve().parent))  # also when imported as bench.bench_server

from _burst import snapshot_after_burst
from _missions import agent_name, library_yaml, mission_yaml, skill_id
from _server_harness import (
    REPO,
    Server,
    ServerClient,
    bench_node,
    figures_printed,
    percentiles,
    ros_master,
    serialized_size,
)
from _whole_mission import WholeMission, subscriber_cpu

__all__ = [  # other benchmarks and tools take these from here
    "REPO",
    "Server",
    "agent_name",
    "library_yaml",
    "mission_yaml",
    "percentiles",
    "ros_master",
]

TARGET = {"p50_ms": 2.0, "p95_ms": 5.0}


class Bench(ServerClient):
    """Times operations against one running server."""

    def __init__(self, agents: int, skills: int, samples: int, seed: int = 1) -> None:
        super().__init__()
        self.agents = [agent_name(i) for i in range(agents)]
        self.skills = skills
        self.samples = samples
        self.rng = random.Random(seed)
        self.label_edits = 0

    def edit_label(self) -> None:
        """One small change, so that the next call meets a new revision.

        A label edit of an inspect skill in the back half of a task, where the per-change
        run's synchronizing never reaches (a synchronized skill cannot be edited).
        """
        self.label_edits += 1
        number = self.label_edits
        last_inspect = self.skills - 1 - (self.skills - 2) % 3
        pv = self.wire.ParameterValue
        self.call(
            "edit_skill",
            base_revision=self.rev,
            skill_id=skill_id(
                number % len(self.agents), last_inspect - 3 * (number % max(1, self.skills // 6))
            ),
            label=f"whole {number}",
            parameters=[pv(name="radius", type=pv.FLOAT, float_value=2.5)],
        )

    def run(self) -> dict[str, dict[str, float]]:
        wire, n = self.wire, self.samples
        pv = wire.ParameterValue
        times: dict[str, list[float]] = {}
        added: list[str] = []

        def record(name: str, elapsed: float) -> None:
            times.setdefault(name, []).append(elapsed)

        for _ in range(n):  # add: append to a random agent
            agent = self.rng.choice(self.agents)
            elapsed, response = self.timed(
                "add_skill",
                base_revision=self.rev,
                agent=agent,
                skill="inspect",
                index=-1,
                parameters=[pv(name="radius", type=pv.FLOAT, float_value=4.0)],
            )
            record("add", elapsed)
            added.append(response.skill_id)
        for number in range(n):  # edit: a parameter and the label of a loaded skill
            agent = self.rng.choice(self.agents)
            skill_id = f"{agent}-s{self.rng.randrange(1, self.skills, 3):05d}"  # an inspect
            elapsed, _ = self.timed(
                "edit_skill",
                base_revision=self.rev,
                skill_id=skill_id,
                label=f"edited {number}",
                parameters=[pv(name="radius", type=pv.FLOAT, float_value=1.0 + number % 9)],
            )
            record("edit", elapsed)
        for skill_id in added:  # delete: what the adds added
            elapsed, _ = self.timed("delete_skills", base_revision=self.rev, skill_ids=[skill_id])
            record("delete", elapsed)
        for _ in range(max(20, n // 5)):  # reorder: a whole blueprint, rotated by one
            agent = self.rng.choice(self.agents)
            task = next(
                t for t in self.call("get_mission").mission.tasks if t.agent == agent
            ).skills
            ids = [s.id for s in task if s.transfer == 0 and s.status.value == 0]
            elapsed, _ = self.timed(
                "reorder_skills", base_revision=self.rev, agent=agent, order=ids[1:] + ids[:1]
            )
            record("reorder", elapsed)
        for _ in range(max(20, n // 5)):  # add barrier: two fresh skills on two agents
            pair = self.rng.sample(self.agents, 2)
            members = [
                self.call(
                    "add_skill", base_revision=self.rev, agent=a, skill="wait", index=-1
                ).skill_id
                for a in pair
            ]
            elapsed, _ = self.timed("add_barrier", base_revision=self.rev, skill_ids=members)
            record("add_barrier", elapsed)
        bound = self.call(
            "add_skill",
            base_revision=self.rev,
            agent=self.agents[0],
            skill="move",
            index=-1,
            parameters=[pv(name="target", type=pv.POSE, marker="Site")],
        )
        del bound
        for number in range(n):  # marker move: one skill bound to it follows
            pose = wire.Pose6D(x=number % 50, y=-(number % 7), yaw=0.1)
            elapsed, _ = self.timed(
                "move_task_marker", base_revision=self.rev, name="Site", pose=pose
            )
            record("marker_move", elapsed)
        for number in range(max(20, n // 5)):  # synchronize: the first blueprint skill
            agent = self.agents[number % len(self.agents)]
            task = next(t for t in self.call("get_mission").mission.tasks if t.agent == agent)
            upto = next(s.id for s in task.skills if s.transfer == 0 and s.status.value == 0)
            elapsed, _ = self.timed(
                "synchronize", base_revision=self.rev, agent=agent, upto_id=upto
            )
            record("sync", elapsed)
        for _ in range(max(10, n // 10)):  # as the project's client reads it, and as genpy
            elapsed, _ = self.timed("get_mission_core")
            record("get_mission", elapsed)
            elapsed, _ = self.timed("get_mission")
            record("get_mission_genpy", elapsed)
        return {name: percentiles(values) for name, values in times.items()}

    def kind_names(self) -> dict[int, str]:
        """The event kinds this benchmark causes, by the name of the operation."""
        return {
            self.wire.MissionEvent.SKILL_ADDED: "add",
            self.wire.MissionEvent.SKILL_EDITED: "edit",
            self.wire.MissionEvent.SKILL_DELETED: "delete",
            self.wire.MissionEvent.SKILLS_REORDERED: "reorder",
            self.wire.MissionEvent.BARRIER_ADDED: "add_barrier",
            self.wire.MissionEvent.MARKER_MOVED: "marker_move",
            self.wire.MissionEvent.SYNC_REQUESTED: "sync",
        }


@dataclasses.dataclass(frozen=True)
class Options:
    """What to measure at one mission size."""

    samples: int  # per per-change operation; 0 skips them
    whole_repeats: int  # of each whole-mission path; 0 skips them
    cpu_seconds: float = 0.0  # of the subscriber measurement; 0 skips it
    profile: Path | None = None  # where a cProfiled server writes its statistics


def bench_size(
    env: dict[str, str], work: Path, agents: int, skills: int, options: Options
) -> dict[str, Any]:
    """Every figure of one mission size, against a server of its own."""
    import rosmc.msg  # noqa: F401  (fail early without the built messages)

    work.mkdir(parents=True, exist_ok=True)
    library = work / "library.yaml"
    library.write_text(library_yaml(agents))
    server = Server(env, work, library, options.profile)
    try:
        bench = Bench(agents, skills, options.samples)
    except BaseException:
        server.stop()
        raise
    try:
        document = mission_yaml(agents, skills)
        rss_before_load = server.rss_mib()
        started = time.perf_counter()
        bench.call("load_mission", base_revision=bench.rev, document=document)
        load_s = time.perf_counter() - started
        time.sleep(0.5)  # the snapshot of the loaded mission is built and journaled
        result: dict[str, Any] = {
            "agents": agents,
            "skills_per_agent": skills,
            "load_document_s": round(load_s, 3),
            "server_rss_before_load_mib": rss_before_load,
            "server_peak_rss_after_load_mib": server.peak_rss_mib(),
        }
        if options.whole_repeats > 0:  # first: a load is refused once skills are synchronized
            whole = WholeMission(bench, server, options.whole_repeats, bench.edit_label)
            result["whole"] = whole.run()
        if options.samples > 0:
            journal_start, changes_start = server.journal_bytes(), bench.changes
            result["latency"] = bench.run()
            time.sleep(1.0)  # let coalesced snapshots land in the journal and events arrive
            changes = bench.changes - changes_start
            result["event_bytes"] = bench.event_bytes(bench.kind_names())
            journaled = server.journal_bytes() - journal_start
            result["journal_bytes_per_change"] = round(journaled / changes)
            result["changes"] = changes
            result["server_peak_rss_after_changes_mib"] = server.peak_rss_mib()
            result["snapshot_after_burst"] = snapshot_after_burst(bench, bench.agents[0])
        if options.cpu_seconds > 0:
            seconds = options.cpu_seconds
            result["snapshot_subscriber"] = subscriber_cpu(bench, server, seconds, bench.edit_label)
        snapshot = bench.call("get_mission").mission
        result["total_skills"] = sum(len(t.skills) for t in snapshot.tasks)
        result["snapshot_bytes"] = serialized_size(snapshot)
        result["server_peak_rss_mib"] = server.peak_rss_mib()
    finally:
        bench.close()
        server.stop()
    return result


def profile_summary(path: Path, top: int = 25) -> list[str]:
    stream = io.StringIO()
    stats = pstats.Stats(str(path), stream=stream)
    stats.sort_stats("tottime").print_stats(top)
    return [line for line in stream.getvalue().splitlines() if line.strip()][-top:]


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", default="2x10,5x100,20x500", help="AGENTSxSKILLS,...")
    parser.add_argument("--samples", type=int, default=300, help="samples per operation")
    parser.add_argument("--profile", action="store_true", help="cProfile the largest size")
    parser.add_argument(
        "--whole-repeats", type=int, default=5, help="times each whole-mission path (0: skip)"
    )
    parser.add_argument(
        "--cpu-seconds",
        type=float,
        default=15.0,
        help="at the largest size, server CPU over this many s of 10 changes/s, "
        "without and with a /rosmc/mission subscriber",
    )
    args = parser.parse_args(argv)
    sizes = [tuple(int(x) for x in size.split("x")) for size in args.sizes.split(",")]
    largest = max(sizes, key=lambda size: size[0] * size[1])
    options = Options(args.samples, args.whole_repeats)
    output: dict[str, Any] = {"target_at_20x500": TARGET, "sizes": []}
    with figures_printed(output), bench_node("bench_server_", "bench_server") as (base, env):
        for a, s in sizes:
            cpu_seconds = args.cpu_seconds if (a, s) == largest else 0.0
            at_size = dataclasses.replace(options, cpu_seconds=cpu_seconds)
            output["sizes"].append(bench_size(env, base / f"{a}x{s}", a, s, at_size))
        if args.profile:
            a, s = largest
            stats = base / "server.prof"
            profiled = dataclasses.replace(options, profile=stats)
            bench_size(env, base / "profiled", a, s, profiled)
            output["profile_top_tottime"] = profile_summary(stats)
    return 0


if __name__ == "__main__":
    sys.exit(main())
