"""Benchmark of the demo mission (``make demo``); prints one JSON object.

Runs ``scripts/rosmc_demo`` (``demo.launch`` on a private master: mission server, sim
node on the default scenario, link emulator, three executors and the scripted operator)
once per real-time factor, 5 and 20 by default, and reports per run:

* ``mission_sim_s`` / ``mission_wall_s``: the scripted mission's duration in sim and wall
  seconds, from the operator's summary (from its start to every skill settled);
* ``achieved_factor``: their ratio;
* ``process_wall_s``: the whole ``rosmc_demo`` run, with start-up and shutdown;
* ``score``, ``stones``, ``operator_changes``, ``revision``: the summary's figures;
* ``journal_bytes``: the size of the mission journal the run wrote (every accepted change
  and robot report, with the snapshots);
* ``exit_code``: 0 if the mission completed.

Run from the repository root::

    source env.sh
    python bench/bench_demo.py [--factors 5 20] [--timeout 600]
"""

from __future__ import annotations

import argparse
import json
import os
import re
import subprocess
import sys
import tempfile
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

REPO = Path(__file__).resolve().parents[1]
DEMO = REPO / "scripts" / "rosmc_demo"
SUMMARY = {
    "score": (r"^score: ([0-9.]+) from \d+ stone", float),
    "stones": (r"^score: [0-9.]+ from (\d+) stone", int),
    "mission_sim_s": (r"^sim time: ([0-9.]+) s, wall time: [0-9.]+ s", float),
    "mission_wall_s": (r"^sim time: [0-9.]+ s, wall time: ([0-9.]+) s", float),
    "operator_changes": (r"^operator changes: (\d+);", int),
    "revision": (r"^operator changes: \d+; mission revision (\d+)", int),
}


def parse_summary(output: str) -> dict[str, Any]:
    """The figures of the operator's closing summary (None where a line is missing)."""
    figures: dict[str, Any] = {}
    for key, (pattern, kind) in SUMMARY.items():
        match = re.search(pattern, output, re.MULTILINE)
        figures[key] = kind(match.group(1)) if match else None
    return figures


def run_demo(factor: float, timeout: float) -> dict[str, Any]:
    """Run the demo at ``factor`` and return its figures."""
    with tempfile.TemporaryDirectory(prefix="bench_demo_") as journal_dir:
        argv = [
            sys.executable,
            str(DEMO),
            "--real-time-factor",
            str(factor),
            "--journal-dir",
            journal_dir,
            "--timeout",
            str(timeout),
        ]
        started = time.monotonic()
        try:
            result = subprocess.run(
                argv,
                cwd=REPO,
                env=dict(os.environ),
                stdin=subprocess.DEVNULL,
                capture_output=True,
                text=True,
                timeout=timeout + 120,
                check=False,
            )
        except subprocess.TimeoutExpired as expired:  # the run's figures are missing, not all
            output = expired.stdout or ""
            text = output.decode(errors="replace") if isinstance(output, bytes) else output
            result = subprocess.CompletedProcess(argv, -9, text, f"killed after {timeout + 120} s")
        wall = time.monotonic() - started
        journal_bytes = sum(f.stat().st_size for f in Path(journal_dir).rglob("*") if f.is_file())
    figures: dict[str, Any] = {"real_time_factor": factor, **parse_summary(result.stdout)}
    sim, mission_wall = figures["mission_sim_s"], figures["mission_wall_s"]
    figures["achieved_factor"] = round(sim / mission_wall, 2) if sim and mission_wall else None
    figures["process_wall_s"] = round(wall, 1)
    figures["journal_bytes"] = journal_bytes
    figures["exit_code"] = result.returncode
    if result.returncode != 0:
        figures["output_tail"] = (result.stdout + result.stderr)[-2000:]
    return figures


def main(argv: Sequence[str] | None = None) -> int:
    """Run the benchmark and print JSON; 1 if a run failed."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument(
        "--factors", type=float, nargs="+", default=[5.0, 20.0], help="real-time factors to run"
    )
    parser.add_argument("--timeout", type=float, default=600.0, help="wall seconds per run")
    args = parser.parse_args(argv)
    runs = [run_demo(factor, args.timeout) for factor in args.factors]
    print(json.dumps({"runs": runs, "cpu_count": os.cpu_count()}, indent=2))
    return 0 if all(run["exit_code"] == 0 for run in runs) else 1


if __name__ == "__main__":
    sys.exit(main())
