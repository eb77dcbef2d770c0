"""The figures of the whole-order and whole-mission paths, side by side with a baseline.

For each size (skills per robot, two robots) and each checkout given (this one, and with
``--baseline DIR`` another checkout of the project, e.g. ``git archive`` of an older
commit with this checkout's ``build`` and ``.venv`` linked in), it starts a real
``mission_server`` on a private rosmaster and loads a generated mission, then times:

* ``reorder_random``: a ``ReorderSkills`` request with the blueprint's whole order,
  shuffled at random (barrier members keep their relative order, so no deadlock), one
  id per ``order`` element; ``reorder_random_lines``: the same with ``order`` as one
  string of lines, as the project's client sends it (only for ``this`` checkout: an
  older server reads that as one id);
* ``add_barrier`` with no other barrier near, in a mission with ten barriers
  (``sparse``), with none (``absent``: the mission's barriers are deleted first) and with
  a barrier on every second skill (``dense``: a mission of its own): two skills near the
  tasks' start, so a search along the barriers after them would walk every one;
* ``get_mission`` (as this checkout's client reads it), ``save`` (to a file),
  ``load`` (of the saved file);
* ``get_mission_own_client``: GetMission as each checkout's own client reads it, in a
  process of its own (``_client_get.py``): the first call (alone, with every skill's
  fields read, and with the ``MissionState`` a client builds), with nothing changed, and
  after an edit of one skill;
* ``add``, ``edit``, ``delete``, ``sync`` p50/p95 (``sync``: the first skill of a
  blueprint, then taken back); ``sync_3000`` / ``unsync_3000``: the first 3,000 skills
  of a blueprint uploaded, then taken back (a cancelled upload: no robot runs);
* the server's peak resident memory after the load and after everything.

Run from the repository root (one size takes about a minute per checkout)::

    source env.sh
    python bench/bench_perf.py [--sizes 5000,10000,24950] [--baseline /tmp/base]
"""

from __future__ import annotations

import argparse
import json
import os
import random
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
sys.path.insert(0, str(Path(__file__).resolve().parent))

from _missions import agent_name, barrier_positions, library_yaml, mission_yaml, skill_id
from _server_harness import REPO, Server, ServerClient, figures_printed, percentiles, ros_master

AGENTS = 2
SYNC_PREFIX = 3000  # skills per synchronize in the figure of a large one
REORDERS = 7  # whole random new orders per figure


class PerfBench(ServerClient):
    """The figures of one mission size against one running server."""

    def __init__(self, per_agent: int, samples: int) -> None:
        super().__init__()
        self.per_agent = per_agent
        self.samples = samples
        self.rng = random.Random(1)

    def p(self, operation: str, calls: int, **fields: Any) -> dict[str, float]:
        """p50/p95 of ``calls`` calls of ``operation`` (revision filled in)."""
        times = []
        for _ in range(calls):
            if "base_revision" in fields:
                fields["base_revision"] = self.rev
            times.append(self.timed(operation, **fields)[0])
        return percentiles(times)

    def reorder_random(self, calls: int, lines: bool = False) -> dict[str, float]:
        """Whole random new orders of robot 0's blueprint, members in their order (with
        ``lines``, ``order`` is one string of the ids joined by line breaks)."""
        times = []
        for _ in range(calls):
            task = next(
                t for t in self.call("get_mission").mission.tasks if t.agent == agent_name(0)
            )
            members = {m for b in self.call("get_mission").mission.barriers for m in b.skill_ids}
            order = [s.id for s in task.skills]
            self.rng.shuffle(order)
            at = [i for i, skill in enumerate(order) if skill in members]
            kept = [s.id for s in task.skills if s.id in members]
            for index, member in zip(at, kept, strict=True):
                order[index] = member
            sent = ["\n".join(order)] if lines else order
            elapsed, _ = self.timed(
                "reorder_skills", base_revision=self.rev, agent=agent_name(0), order=sent
            )
            times.append(elapsed)
        return percentiles(times)

    def add_barrier_near_start(self, calls: int) -> dict[str, float]:
        """Barriers over free skills near the tasks' start (each deleted again)."""
        times = []
        for number in range(calls):
            pair = [skill_id(agent, 1 + 2 * number) for agent in range(AGENTS)]
            elapsed, answer = self.timed("add_barrier", base_revision=self.rev, skill_ids=pair)
            times.append(elapsed)
            self.call("delete_barrier", base_revision=self.rev, barrier_id=answer.barrier_id)
        return percentiles(times)

    def whole(self, calls: int) -> dict[str, Any]:
        """get_mission (core), save to a file, load of that file."""
        got = self.p("get_mission_core", calls)
        save = self.p("save_mission", calls, path="bench.yaml")
        load = self.p("load_mission", calls, base_revision=0, path="bench.yaml")
        return {"get_mission": got, "save": save, "load": load}

    def per_change(self) -> dict[str, Any]:
        """add, edit, delete, sync p50/p95."""
        pv = self.wire.ParameterValue
        added, times = [], {"add": [], "edit": [], "delete": [], "sync": []}
        for number in range(self.samples):
            elapsed, answer = self.timed(
                "add_skill", base_revision=self.rev, agent=agent_name(number % 2), skill="wait"
            )
            times["add"].append(elapsed)
            added.append(answer.skill_id)
            elapsed, _ = self.timed(
                "edit_skill",
                base_revision=self.rev,
                skill_id=skill_id(number % 2, 4),
                parameters=[pv(name="radius", type=pv.FLOAT, float_value=1.0 + number % 9)],
            )
            times["edit"].append(elapsed)
        for added_id in added:
            times["delete"].append(
                self.timed("delete_skills", base_revision=self.rev, skill_ids=[added_id])[0]
            )
        # The first skill of each blueprint as it is now (the random reorders moved them).
        tasks = {task.agent: task.skills for task in self.call("get_mission").mission.tasks}
        for number in range(self.samples):
            agent = agent_name(number % 2)
            first = tasks[agent][0].id
            times["sync"].append(
                self.timed("synchronize", base_revision=self.rev, agent=agent, upto_id=first)[0]
            )
            self.call("unsynchronize", base_revision=self.rev, agent=agent)
        figures = {name: percentiles(values) for name, values in times.items()}
        figures.update(self.sync_prefix(tasks, SYNC_PREFIX))
        return figures

    def sync_prefix(self, tasks: dict[str, Any], skills: int) -> dict[str, Any]:
        """Synchronize (then take back) the first ``skills`` skills of a blueprint."""
        times: dict[str, list[float]] = {"sync": [], "unsync": []}
        for number in range(max(4, self.samples // 10)):
            agent = agent_name(number % 2)
            upto = tasks[agent][min(skills, len(tasks[agent])) - 1].id
            for name, operation, fields in (
                ("sync", "synchronize", {"upto_id": upto}),
                ("unsync", "unsynchronize", {}),
            ):
                elapsed = self.timed(operation, base_revision=self.rev, agent=agent, **fields)[0]
                times[name].append(elapsed)
        return {f"{name}_{skills}": percentiles(values) for name, values in times.items()}


def client_get(env: dict[str, str], repo: Path, calls: int) -> Any:
    """GetMission as the client code of ``repo`` reads it (see ``_client_get.py``)."""
    child_env = dict(env, PYTHONPATH=os.pathsep.join([str(repo), env.get("PYTHONPATH", "")]))
    script = Path(__file__).resolve().parent / "_client_get.py"
    argv = [sys.executable, str(script), str(repo), skill_id(0, 4), "radius", str(calls)]
    done = subprocess.run(argv, env=child_env, capture_output=True, text=True, timeout=600)
    if done.returncode != 0:
        return {"error": done.stderr[-2000:]}
    return json.loads(done.stdout.strip().splitlines()[-1])


def run(env: dict[str, str], work: Path, repo: Path, per_agent: int, samples: int) -> Any:
    """Every figure of one size against the server of ``repo``."""
    work.mkdir(parents=True, exist_ok=True)
    library = work / "library.yaml"
    library.write_text(library_yaml(AGENTS))
    result: dict[str, Any] = {}
    for layout, barriers in (("sparse", 10), ("dense", per_agent // 2)):
        (work / layout).mkdir()
        server = Server(env, work / layout, library, None, repo=repo)
        try:
            bench = PerfBench(per_agent, samples)
            try:
                document = mission_yaml(AGENTS, per_agent, barriers)
                bench.call("load_mission", base_revision=bench.rev, document=document)
                time.sleep(1.0)
                if layout == "dense":
                    result["add_barrier_dense"] = bench.add_barrier_near_start(samples // 4)
                    continue
                result["peak_rss_after_load_mib"] = server.peak_rss_mib()
                result["add_barrier_sparse"] = bench.add_barrier_near_start(samples // 4)
                result.update(bench.whole(5))
                result["get_mission_own_client"] = client_get(env, repo, 5)
                bench.rev = bench.call("get_mission").mission.revision  # it edited a skill
                result["reorder_random"] = bench.reorder_random(REORDERS)
                if repo == REPO:
                    result["reorder_random_lines"] = bench.reorder_random(REORDERS, lines=True)
                result["per_change"] = bench.per_change()
                for number in barrier_positions(per_agent, barriers):
                    barrier = f"barrier-{number:05d}"
                    bench.call("delete_barrier", base_revision=bench.rev, barrier_id=barrier)
                result["add_barrier_absent"] = bench.add_barrier_near_start(samples // 4)
                result["peak_rss_mib"] = server.peak_rss_mib()
            finally:
                bench.close()
        finally:
            server.stop()
    return result


def main(argv: list[str] | None = None) -> int:
    """Measure every size for this checkout (and the baseline); print the figures."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    # 24,950, not 25,000: the per-change figures add skills, and a mission holds 50,000 at most.
    parser.add_argument("--sizes", default="5000,10000,24950", help="skills per robot, ...")
    parser.add_argument("--samples", type=int, default=100, help="calls per per-change figure")
    parser.add_argument("--baseline", type=Path, help="another checkout to measure alike")
    args = parser.parse_args(argv)
    trees = {"this": REPO}
    if args.baseline:
        trees["baseline"] = args.baseline.resolve()
    figures: dict[str, Any] = {"agents": AGENTS, "trees": {k: str(v) for k, v in trees.items()}}
    with figures_printed(figures), tempfile.TemporaryDirectory(prefix="bench_perf_") as tmp:
        base = Path(tmp)
        with ros_master(base) as env:
            import rospy

            rospy.init_node("bench_perf", anonymous=True, disable_signals=True)
            for per_agent in (int(n) for n in args.sizes.split(",") if n):
                for name, repo in trees.items():
                    work = base / f"{name}-{per_agent}"
                    figures.setdefault(name, {})[str(per_agent)] = run(
                        env, work, repo, per_agent, args.samples
                    )
            rospy.signal_shutdown("done")
    return 0


if __name__ == "__main__":
    sys.exit(main())
