#!/usr/bin/env python3
"""Benchmark of the command window's start: process start -> rows painted; prints JSON.

A private rosmaster and a real ``mission_server`` hold a mission of each ``--sizes`` entry
(robots x skills per robot). The ``rosmc_command`` window is then started as a process
(offscreen Qt, ``--startup-report``) ``--repeats`` times; from the moment before the
process is spawned it times (median of the runs, seconds):

* ``main``: the imports done (``main()`` entered); ``node``: the ROS node registered;
* ``window``: the empty window painted; ``snapshot``: the mission snapshot fetched and
  read into the process (before the window takes it);
* ``rows``: the first rows painted (``first_rows_s``, the figure of issue 23, wanted
  <= 1.0 s); ``all``: every row of the mission shown (``all_rows_s``).

Python's bytecode cache is kept in a private folder (``PYTHONPYCACHEPREFIX``) even where
``PYTHONDONTWRITEBYTECODE`` is set, as an installed program has its modules compiled: a
first run fills it, the ``--repeats`` after it read it (without it, compiling the
project's modules adds about 0.3 s to every start).

Beside it, in the same run, the cost floor no GUI can go below: a process that imports
``rospy`` and ``rosmc.msg`` and paints an empty Qt window (``floor_s``), and
``overhead_over_floor_s`` = ``first_rows_s`` - ``floor_s``. The snapshot's own costs are
measured in this process: ``fetch_ms`` (GetMission answered, bytes undecoded) and
``decode_ms`` (those bytes read into core objects as the window reads them).

Usage: ``python bench/bench_command_gui_start.py [--sizes 2x5000,20x500 --repeats 3]``.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from bench._missions import library_yaml, mission_yaml  # noqa: E402
from bench._server_harness import Server, raw_proxy, ros_master, stop_process  # noqa: E402

TARGET_FIRST_ROWS_S = 1.0
STAGES = ("main", "node", "window", "snapshot", "rows", "all")

# The floor: what any ROS + Qt window pays before it can show anything.
FLOOR = """
import sys, time
import rospy, rosmc.msg
from python_qt_binding.QtCore import QEvent, QObject, QTimer
from python_qt_binding.QtWidgets import QApplication, QLabel, QMainWindow
app = QApplication([sys.argv[0]])
window = QMainWindow()
window.setCentralWidget(QLabel("floor"))
window.resize(1560, 920)
class Painted(QObject):
    def eventFilter(self, watched, event):
        if event.type() == QEvent.Paint:
            QTimer.singleShot(0, lambda: (print(time.monotonic(), flush=True), app.quit()))
        return False
painted = Painted()
window.installEventFilter(painted)
window.show()
app.exec_()
"""


def run_floor(env: dict[str, str]) -> float:
    """Seconds from spawning the floor process to its empty window painted."""
    started = time.monotonic()
    out = subprocess.run(
        [sys.executable, "-c", FLOOR], env=env, capture_output=True, text=True, timeout=60
    )
    return float(out.stdout.split()[-1]) - started


def run_window(env: dict[str, str], work: Path) -> dict[str, float]:
    """Seconds from spawning ``rosmc_command`` to each start-up stage it reported."""
    report = work / "startup.jsonl"
    report.unlink(missing_ok=True)
    with (work / "window.log").open("wb") as log:
        started = time.monotonic()
        process = subprocess.Popen(
            [sys.executable, str(REPO / "scripts" / "rosmc_command"), "--startup-report", report],
            env=env,
            stdout=log,
            stderr=subprocess.STDOUT,
            start_new_session=True,
        )
    stages: dict[str, float] = {}
    try:
        deadline = time.monotonic() + 120
        while not {"rows", "all"} <= stages.keys():
            if process.poll() is not None or time.monotonic() > deadline:
                log = (work / "window.log").read_text()[-2000:]
                raise RuntimeError(f"the window did not show the mission:\n{log}")
            time.sleep(0.02)
            if report.exists():
                for line in report.read_text().splitlines():
                    if line.endswith("}"):
                        mark = json.loads(line)
                        stages[mark["stage"]] = mark["t"] - started
    finally:
        stop_process(process, grace=10.0)
    return stages


def snapshot_costs(repeats: int) -> dict[str, float]:
    """GetMission's answer time (bytes undecoded) and the window's decode of those bytes."""
    from rosmc_server.conversions.unpacking import UnpackedGetMissionResponse

    proxy = raw_proxy("get_mission")
    fetch, decode = [], []
    for _ in range(repeats):
        started = time.perf_counter()
        raw = proxy.call(proxy.request_class()).raw
        fetch.append(time.perf_counter() - started)
        started = time.perf_counter()
        UnpackedGetMissionResponse().deserialize(raw)
        decode.append(time.perf_counter() - started)
    proxy.close()
    return {
        "fetch_ms": round(statistics.median(fetch) * 1000, 1),
        "decode_ms": round(statistics.median(decode) * 1000, 1),
        "snapshot_bytes": len(raw),
    }


def bench_size(
    env: dict[str, str], work: Path, agents: int, skills: int, repeats: int
) -> dict[str, Any]:
    """Every figure for one mission size."""
    library = work / f"library_{agents}.yaml"
    library.write_text(library_yaml(agents))
    server = Server(env, work, library, None)
    try:
        from rosmc_server.ros.client import MissionClient

        with MissionClient(60.0) as client:
            client.get_mission()
            client.load_mission(mission_yaml(agents, skills))
        env = dict(env, PYTHONPYCACHEPREFIX=str(work / f"pycache_{agents}x{skills}"))
        env.pop("PYTHONDONTWRITEBYTECODE", None)
        run_window(env, work)  # fills the cache
        runs = [run_window(env, work) for _ in range(repeats)]
        floors = [run_floor(env) for _ in range(repeats)]
        costs = snapshot_costs(repeats)
    finally:
        server.stop()
    stages = {s: round(statistics.median(r[s] for r in runs), 3) for s in STAGES if s in runs[0]}
    floor = statistics.median(floors)
    return {
        "agents": agents,
        "skills_per_agent": skills,
        "first_rows_s": stages["rows"],
        "all_rows_s": stages["all"],
        "floor_s": round(floor, 3),
        "overhead_over_floor_s": round(stages["rows"] - floor, 3),
        "stages_s": stages,
        "first_rows_runs_s": [round(r["rows"], 3) for r in runs],
        **costs,
    }


def main() -> int:
    """Run the benchmark; print JSON."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", default="2x5000,20x500", help="robots x skills, comma-separated")
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    figures: dict[str, Any] = {"target_first_rows_s": TARGET_FIRST_ROWS_S, "sizes": {}}
    with tempfile.TemporaryDirectory() as tmp, ros_master(Path(tmp)) as env:
        env = dict(env, QT_QPA_PLATFORM="offscreen")
        import rospy

        rospy.init_node("bench_command_gui_start", anonymous=True, disable_signals=True)
        for size in args.sizes.split(","):
            agents, skills = (int(n) for n in size.lower().split("x"))
            figures["sizes"][size] = bench_size(env, Path(tmp), agents, skills, args.repeats)
        rospy.signal_shutdown("done")
    print(json.dumps(figures, indent=2))
    return 0


if __name__ == "__main__":
    os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")
    sys.exit(main())
