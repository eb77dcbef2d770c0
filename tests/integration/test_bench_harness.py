"""bench/_server_harness.py: a benchmark prints its figures whatever its signal disposition.

A benchmark run in the background of a script, under ``nohup`` or in some CI shells starts
with SIGINT ignored, and so does every process it starts: a ``rosmaster`` then never stops
on SIGINT. A real rosmaster is started through the harness by a small benchmark-like
script, with SIGINT ignored from the start; the script must end, print its figures and
leave no master behind. Stopped by SIGTERM midway (``run_all.py``'s timeout), it prints
what it had measured and stops its master too.
"""

from __future__ import annotations

import json
import os
import signal
import socket
import subprocess
import sys
from pathlib import Path
from typing import Any

REPO = Path(__file__).resolve().parents[2]
BENCH_SCRIPT = """
import sys, time
sys.path.insert(0, {bench!r})
from pathlib import Path
from _server_harness import figures_printed, ros_master

figures = {{}}
with figures_printed(figures), ros_master(Path({home!r})) as env:
    figures["master"] = env["ROS_MASTER_URI"]
    figures["measured"] = 1
    print("measuring", file=sys.stderr, flush=True)
    time.sleep({sleep})
    figures["measured"] = 2
"""


def start(tmp_path: Path, sleep: float) -> subprocess.Popen[str]:
    """The script, started with SIGINT ignored (as ``nohup`` or ``cmd &`` in a script do)."""
    home = tmp_path / "home"
    (home / "log").mkdir(parents=True)
    code = BENCH_SCRIPT.format(bench=str(REPO / "bench"), home=str(home), sleep=sleep)
    return subprocess.Popen(
        [sys.executable, "-c", code],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_IGN),
        start_new_session=True,
    )


def master_answers(uri: str) -> bool:
    host, port = uri.removeprefix("http://").rstrip("/").split(":")
    with socket.socket() as sock:
        sock.settimeout(2.0)
        return sock.connect_ex((host, int(port))) == 0


def finish(process: subprocess.Popen[str]) -> tuple[Any, str]:
    try:
        out, err = process.communicate(timeout=120)
    except subprocess.TimeoutExpired:  # the old harness waited for the master for ever
        os.killpg(process.pid, signal.SIGKILL)
        out, err = process.communicate()
        raise AssertionError(f"the benchmark did not end:\n{err[-2000:]}") from None
    return json.loads(out), err


def test_a_benchmark_with_sigint_ignored_stops_its_master_and_prints_its_figures(
    tmp_path: Path,
) -> None:
    process = start(tmp_path, sleep=0.0)
    figures, err = finish(process)
    assert process.returncode == 0, err[-2000:]
    assert figures["measured"] == 2 and "interrupted" not in figures
    assert not master_answers(figures["master"])


def test_sigterm_prints_what_was_measured_and_stops_the_master(tmp_path: Path) -> None:
    process = start(tmp_path, sleep=600.0)
    assert process.stderr is not None
    assert "measuring" in process.stderr.readline()
    os.killpg(process.pid, signal.SIGTERM)
    figures, err = finish(process)
    assert process.returncode == 128 + signal.SIGTERM, err[-2000:]
    assert figures["measured"] == 1
    assert figures["interrupted"] == f"SystemExit: {128 + signal.SIGTERM}"
    assert not master_answers(figures["master"])
