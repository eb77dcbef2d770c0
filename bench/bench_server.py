"""Benchmark of the mission server's operator services; prints one JSON object.

Starts its own ``rosmaster`` on a free loopback port and, per mission size (agents x
skills per agent), a real ``mission_server`` on a generated library of that many dynamic
agents. The mission is loaded as one document, then each operation is timed from a
client with persistent service proxies: median and p95 latency of add, edit, delete,
reorder, add barrier, marker move, synchronize and get_mission; bytes per event, per
snapshot and per journaled change; the server's peak RSS. Run from the repository root::

    source env.sh
    python bench/bench_server.py [--sizes 2x10,5x100,20x500] [--samples 300] [--profile]

``--profile`` runs the largest size a second time under cProfile (every server thread)
and adds the top functions by internal time to the output.
"""

from __future__ import annotations

import argparse
import io
import pstats
import random
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
sys.path.insert(0, str(Path(__file__).resolve().parent))  # also when imported as bench.bench_server

from _server_harness import (
    REPO,
    Server,
    ServerClient,
    agent_name,
    figures_printed,
    library_yaml,
    mission_yaml,
    percentiles,
    ros_master,
    serialized_size,
)

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
        for _ in range(max(10, n // 10)):
            elapsed, _ = self.timed("get_mission")
            record("get_mission", elapsed)
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


def bench_size(
    env: dict[str, str], work: Path, agents: int, skills: int, samples: int, profile: Path | None
) -> dict[str, Any]:
    import rosmc.msg  # noqa: F401  (fail early without the built messages)

    work.mkdir(parents=True, exist_ok=True)
    library = work / "library.yaml"
    library.write_text(library_yaml(agents))
    server = Server(env, work, library, profile)
    try:
        bench = Bench(agents, skills, samples)
    except BaseException:
        server.stop()
        raise
    try:
        document = mission_yaml(agents, skills)
        started = time.perf_counter()
        bench.call("load_mission", base_revision=bench.rev, document=document)
        load_s = time.perf_counter() - started
        time.sleep(0.5)  # the snapshot of the loaded mission is built and journaled
        journal_start, changes_start = server.journal_bytes(), bench.changes
        latencies = bench.run()
        time.sleep(1.0)  # let coalesced snapshots land in the journal and events arrive
        changes = bench.changes - changes_start
        snapshot = bench.call("get_mission").mission
        result = {
            "agents": agents,
            "skills_per_agent": skills,
            "total_skills": sum(len(t.skills) for t in snapshot.tasks),
            "load_document_s": round(load_s, 3),
            "latency": latencies,
            "event_bytes": bench.event_bytes(bench.kind_names()),
            "snapshot_bytes": serialized_size(snapshot),
            "journal_bytes_per_change": round((server.journal_bytes() - journal_start) / changes),
            "changes": changes,
            "server_peak_rss_mib": server.peak_rss_mib(),
        }
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
    args = parser.parse_args(argv)
    sizes = [tuple(int(x) for x in size.split("x")) for size in args.sizes.split(",")]
    output: dict[str, Any] = {"target_at_20x500": TARGET, "sizes": []}
    with figures_printed(output), tempfile.TemporaryDirectory(prefix="bench_server_") as tmp:
        base = Path(tmp)
        (base / "log").mkdir()
        with ros_master(base) as env:
            import rospy

            rospy.init_node("bench_server", anonymous=True, disable_signals=True)
            for a, s in sizes:
                output["sizes"].append(bench_size(env, base / f"{a}x{s}", a, s, args.samples, None))
            if args.profile:
                a, s = max(sizes, key=lambda size: size[0] * size[1])
                stats = base / "server.prof"
                bench_size(env, base / "profiled", a, s, args.samples, stats)
                output["profile_top_tottime"] = profile_summary(stats)
            rospy.signal_shutdown("done")
    return 0


if __name__ == "__main__":
    sys.exit(main())
