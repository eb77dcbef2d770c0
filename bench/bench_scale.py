"""Scale benchmark: every operator operation from 10 to 10,000 skills; prints one JSON object.

Per mission size (total skills, two robots with half each, and barriers across both tasks
at evenly spread places: ten from 100 skills on, one at 10, so the deadlock check has
barriers to follow) it starts a real ``mission_server`` (private rosmaster, persistent
service proxies; see ``_server_harness.py``), loads the mission as one document and times:

* per-change operations, p50 and p95 of ``--samples`` calls and the bytes of the event
  each publishes: ``add`` (append a skill), ``edit`` (a parameter and the label),
  ``delete`` (what ``add`` added), ``add_barrier`` (two free skills between the same two
  existing barriers: the check follows every barrier after them) and ``delete_barrier``
  (that barrier again), ``marker_move`` (a task marker one skill is bound to), ``sync``
  (upload the first blueprint skill) and ``unsync`` (take it back: no robot answers in
  this benchmark, so the pending upload is cancelled), ``reorder`` (a ``ReorderSkills``
  request with one move: a skill in no barrier to a random place of its blueprint);
* ``reorder_whole``: the same change requested as the blueprint's whole new order, a
  request that grows with the blueprint by nature (its event carries the one move);
* whole-mission operations, p50 and p95 of a few calls: ``get_mission`` (read into core
  objects, as the project's client reads it; ``get_mission_genpy``: into genpy messages,
  as any rospy client), ``save`` (the document in the answer) and ``load`` (the saved
  document), with their bytes;
* ``spaced_edit``: edits 60 ms apart (``--spaced`` of them), at each size and at 700
  skills, where the latched snapshot is rebuilt between changes.

For every per-change operation it prints p50 at 10,000 skills over p50 at 100 (target
at most 1.5) and lists those over the target. Run from the repository root::

    source env.sh
    python bench/bench_scale.py [--sizes 10,100,1000,5000,10000] [--samples 300]
"""

from __future__ import annotations

import argparse
import random
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
sys.path.insert(0, str(Path(__file__).resolve().parent))

from _missions import agent_name, barrier_positions, library_yaml, mission_yaml, skill_id
from _server_harness import (
    Server,
    ServerClient,
    figures_printed,
    percentiles,
    ros_master,
    serialized_size,
)

AGENTS = 2
TARGET_RATIO = 1.5
RATIO_SIZES = (100, 10000)
PER_CHANGE = (
    "add",
    "edit",
    "delete",
    "reorder",
    "add_barrier",
    "delete_barrier",
    "marker_move",
    "sync",
    "unsync",
)
SPACING_S = 0.06


def barrier_count(per_agent: int) -> int:
    """Barriers in the loaded mission: ten, or fewer where a task is too short for ten."""
    return min(10, per_agent // 5)


class ScaleBench(ServerClient):
    """The operations of one mission size against one running server."""

    def __init__(self, per_agent: int, samples: int, seed: int = 1) -> None:
        super().__init__()
        self.per_agent = per_agent
        self.samples = samples
        self.rng = random.Random(seed)
        self.agents = [agent_name(i) for i in range(AGENTS)]
        self.members = set(barrier_positions(per_agent, barrier_count(per_agent)))
        self.times: dict[str, list[float]] = {}

    def kind_names(self) -> dict[int, str]:
        """The operation behind each event kind this benchmark causes."""
        event = self.wire.MissionEvent
        return {
            event.SKILL_ADDED: "add",
            event.SKILL_EDITED: "edit",
            event.SKILL_DELETED: "delete",
            event.SKILLS_REORDERED: "reorder",
            event.BARRIER_ADDED: "add_barrier",
            event.BARRIER_DELETED: "delete_barrier",
            event.MARKER_MOVED: "marker_move",
            event.SYNC_REQUESTED: "sync",
            event.UPLOAD_CANCELLED: "unsync",
        }

    def timed_as(self, figure: str, operation: str, /, **fields: Any) -> Any:
        """Call ``operation`` on the current revision; its time counts for ``figure``."""
        if operation not in ("get_mission", "get_mission_core", "save_mission"):
            fields.setdefault("base_revision", self.rev)
        elapsed, response = self.timed(operation, **fields)
        self.times.setdefault(figure, []).append(elapsed)
        return response

    def free_skill(self, agent: int, low: int = 0, high: int | None = None) -> str:
        """A loaded skill in no barrier, numbered from ``low`` up to ``high``."""
        high = self.per_agent if high is None else high
        while True:
            number = self.rng.randrange(low, high)
            if number not in self.members:
                return skill_id(agent, number)

    # -- the operations, in an order that keeps every request valid ---------------------------
    def edits(self) -> None:
        """Add, edit, delete."""
        pv = self.wire.ParameterValue
        added = []
        for _ in range(self.samples):
            response = self.timed_as(
                "add",
                "add_skill",
                agent=self.rng.choice(self.agents),
                skill="inspect",
                index=-1,
                parameters=[pv(name="radius", type=pv.FLOAT, float_value=4.0)],
            )
            added.append(response.skill_id)
        for number in range(self.samples):
            agent = self.rng.randrange(AGENTS)
            inspect = self.rng.randrange(1, self.per_agent, 3)  # the inspect skills
            self.timed_as(
                "edit",
                "edit_skill",
                skill_id=skill_id(agent, inspect),
                label=f"edited {number}",
                parameters=[pv(name="radius", type=pv.FLOAT, float_value=1.0 + number % 9)],
            )
        for added_id in added:
            self.timed_as("delete", "delete_skills", skill_ids=[added_id])

    def barriers(self) -> None:
        """Add a barrier between the same two existing ones on both tasks, delete it again."""
        places = sorted(self.members)
        for _ in range(self.samples):
            gap = self.rng.randrange(len(places)) if places else 0
            low = places[gap] + 1 if places else 0
            high = places[gap + 1] if gap + 1 < len(places) else self.per_agent
            if high <= low:
                continue
            pair = [self.free_skill(agent, low, high) for agent in range(AGENTS)]
            barrier = self.timed_as("add_barrier", "add_barrier", skill_ids=pair).barrier_id
            self.timed_as("delete_barrier", "delete_barrier", barrier_id=barrier)

    def marker_moves(self) -> None:
        """Move the task marker one skill is bound to."""
        pv = self.wire.ParameterValue
        self.call(
            "add_skill",
            base_revision=self.rev,
            agent=self.agents[0],
            skill="move",
            index=-1,
            parameters=[pv(name="target", type=pv.POSE, marker="Site")],
        )
        for number in range(self.samples):
            pose = self.wire.Pose6D(x=number % 50, y=-(number % 7), yaw=0.1)
            self.timed_as("marker_move", "move_task_marker", name="Site", pose=pose)

    def transfers(self) -> None:
        """Synchronize a robot's first blueprint skill, then take it back."""
        for number in range(self.samples):
            agent = number % AGENTS
            first = skill_id(agent, 0)
            self.timed_as("sync", "synchronize", agent=self.agents[agent], upto_id=first)
            self.timed_as("unsync", "unsynchronize", agent=self.agents[agent])

    def reorders(self) -> None:
        """Move a skill in no barrier: as one move, then as the blueprint's whole order."""
        move = self.wire.SkillMove
        for _ in range(self.samples):
            agent = self.rng.randrange(AGENTS)
            to = self.rng.randrange(self.per_agent)
            moves = [move(skill_id=self.free_skill(agent), index=to)]
            self.timed_as("reorder", "reorder_skills", agent=self.agents[agent], moves=moves)
        tasks = {t.agent: [s.id for s in t.skills] for t in self.call("get_mission").mission.tasks}
        for _ in range(max(10, self.samples // 10)):
            agent = self.rng.randrange(AGENTS)
            order = tasks[self.agents[agent]]
            order.remove(moved := self.free_skill(agent))
            order.insert(self.rng.randrange(self.per_agent), moved)
            self.timed_as("reorder_whole", "reorder_skills", agent=self.agents[agent], order=order)

    def whole(self, document: str, calls: int) -> dict[str, int]:
        """Get, save and load the whole mission; the bytes each moves.

        The load is of the document the server saved (what an operator loads back), not of
        the generated one, which YAML reads the slow way.
        """
        sizes = {}
        for _ in range(calls):
            self.timed_as("get_mission", "get_mission_core")
            answer = self.timed_as("get_mission_genpy", "get_mission")
            sizes["get_mission"] = serialized_size(answer)
        saved = document
        for _ in range(calls):
            saved = self.timed_as("save", "save_mission", path="").document
            sizes["save"] = len(saved.encode())
        sizes["load"] = len(saved.encode())
        for _ in range(calls):
            self.timed_as("load", "load_mission", document=saved)
        return sizes

    def spaced_edits(self, count: int) -> dict[str, float]:
        """Edits ``SPACING_S`` apart: each finds the server between snapshot rebuilds."""
        times: list[float] = []
        for number in range(count):
            time.sleep(SPACING_S)
            elapsed, _ = self.timed(
                "edit_skill",
                base_revision=self.rev,
                skill_id=skill_id(number % AGENTS, 1),
                label=f"spaced {number}",
            )
            times.append(elapsed)
        return percentiles(times)


def run_size(
    env: dict[str, str], work: Path, total: int, samples: int, spaced: int, full: bool
) -> dict[str, Any]:
    """Start a server on a mission of ``total`` skills and measure it (``full``: every
    operation, else the spaced edits only)."""
    per_agent = total // AGENTS
    work.mkdir(parents=True, exist_ok=True)
    library = work / "library.yaml"
    library.write_text(library_yaml(AGENTS))
    document = mission_yaml(AGENTS, per_agent, barrier_count(per_agent))
    server = Server(env, work, library, None)
    try:
        bench = ScaleBench(per_agent, samples)
        try:
            started = time.perf_counter()
            bench.call("load_mission", base_revision=bench.rev, document=document)
            result: dict[str, Any] = {
                "skills": per_agent * AGENTS,
                "barriers": barrier_count(per_agent),
                "first_load_s": round(time.perf_counter() - started, 3),
            }
            time.sleep(1.0)  # the loaded mission's snapshot is built and published
            if full:
                bench.edits()
                bench.barriers()
                bench.marker_moves()
                bench.transfers()
                bench.reorders()
                time.sleep(0.5)  # the last events arrive
                result["event_bytes"] = bench.event_bytes(bench.kind_names())
                result["whole_bytes"] = bench.whole(document, 5)
                result["latency"] = {n: percentiles(t) for n, t in bench.times.items()}
            result["spaced_edit"] = bench.spaced_edits(spaced)
            result["server_peak_rss_mib"] = server.peak_rss_mib()
        finally:
            bench.close()
    finally:
        server.stop()
    return result


def ratios(sizes: dict[str, Any]) -> dict[str, float]:
    """p50 at the larger over p50 at the smaller of RATIO_SIZES, per per-change operation."""
    small, large = (sizes.get(str(n), {}).get("latency") for n in RATIO_SIZES)
    if not small or not large:
        return {}
    return {
        name: round(large[name]["p50_ms"] / small[name]["p50_ms"], 2)
        for name in (*PER_CHANGE, "reorder_whole")
        if name in small and name in large
    }


def main(argv: list[str] | None = None) -> int:
    """Measure every size; print the figures (also the partial ones of an interrupted run)."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", default="10,100,1000,5000,10000", help="total skills, ...")
    parser.add_argument("--samples", type=int, default=300, help="calls per operation")
    parser.add_argument("--spaced", type=int, default=60, help="spaced edits per size")
    parser.add_argument("--spaced-extra", default="700", help="sizes with spaced edits only")
    args = parser.parse_args(argv)
    sizes = [int(n) for n in args.sizes.split(",") if n]
    extra = [int(n) for n in args.spaced_extra.split(",") if n]
    figures: dict[str, Any] = {
        "agents": AGENTS,
        "samples": args.samples,
        "target_ratio": TARGET_RATIO,
        "sizes": {},
    }
    with figures_printed(figures), tempfile.TemporaryDirectory(prefix="bench_scale_") as tmp:
        base = Path(tmp)
        (base / "log").mkdir()
        with ros_master(base) as env:
            import rospy

            rospy.init_node("bench_scale", anonymous=True, disable_signals=True)
            for total in sorted({*sizes, *extra}):
                work = base / str(total)
                result = run_size(env, work, total, args.samples, args.spaced, total in sizes)
                figures["sizes"][str(total)] = result
            rospy.signal_shutdown("done")
        figures[f"ratio_p50_{RATIO_SIZES[1]}_vs_{RATIO_SIZES[0]}"] = found = ratios(
            figures["sizes"]
        )
        figures["over_target"] = [
            name for name in PER_CHANGE if found.get(name, 0.0) > TARGET_RATIO
        ]
    return 0


if __name__ == "__main__":
    sys.exit(main())
