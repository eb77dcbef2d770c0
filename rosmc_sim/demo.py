"""``rosmc_demo``: run the headless demo mission end to end and report on it.

Starts ``roslaunch rosmc demo.launch`` with its own ROS master on a free
loopback port (so it never disturbs another ROS system on the machine),
streams its output, and exits with the scripted operator's result. The
mission's MCAP recording stays under ``bags/``.
"""

from __future__ import annotations

import argparse
import os
import signal
import socket
import subprocess
import sys
import tempfile
import time
from collections.abc import Sequence
from pathlib import Path

PACKAGE_ROOT = Path(__file__).resolve().parents[1]


def free_port() -> int:
    """A free TCP port on the loopback interface."""
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as sock:
        sock.bind(("127.0.0.1", 0))
        port: int = sock.getsockname()[1]
        return port


def newest_recording(directory: Path, since: float) -> Path | None:
    """The newest ``.mcap`` file written in ``directory`` after ``since``."""
    files = [p for p in directory.glob("*.mcap") if p.stat().st_mtime >= since]
    return max(files, key=lambda p: p.stat().st_mtime) if files else None


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of ``rosmc_demo``."""
    parser = argparse.ArgumentParser(
        prog="rosmc_demo",
        description="Run the ROSMC sample-return demo mission headless: mission server, "
        "simulated team and a scripted operator, on a private ROS master.",
    )
    parser.add_argument(
        "--real-time-factor",
        type=float,
        default=5.0,
        help="simulation speed; 1 = real time (default 5)",
    )
    parser.add_argument(
        "--latency",
        type=float,
        default=0.0,
        help="one-way ground-robot link latency in sim seconds",
    )
    parser.add_argument("--timeout", type=float, default=600.0, help="give up after (wall s)")
    parser.add_argument(
        "--journal-dir",
        default=str(PACKAGE_ROOT / "bags"),
        help="where the mission recording goes (default: bags/)",
    )
    args = parser.parse_args(
        [a for a in (argv if argv is not None else sys.argv[1:]) if ":=" not in a]
    )
    port = free_port()
    journal_dir = Path(args.journal_dir).resolve()
    journal_dir.mkdir(parents=True, exist_ok=True)
    home = tempfile.mkdtemp(prefix="rosmc_demo_")
    env = dict(
        os.environ, ROS_MASTER_URI=f"http://127.0.0.1:{port}", ROS_IP="127.0.0.1", ROS_HOME=home
    )
    env.pop("ROS_HOSTNAME", None)
    result = Path(home) / "operator_result"
    command = [
        "roslaunch",
        "-p",
        str(port),
        "rosmc",
        "demo.launch",
        f"real_time_factor:={args.real_time_factor}",
        f"latency:={args.latency}",
        f"journal_dir:={journal_dir}",
        f"timeout:={args.timeout}",
        f"result_file:={result}",
    ]
    started = time.time()
    print(f"rosmc_demo: ROS master on port {port}; recording into {journal_dir}", flush=True)
    process = subprocess.Popen(command, env=env, start_new_session=True)
    try:
        process.wait(timeout=args.timeout + 60)
    except (subprocess.TimeoutExpired, KeyboardInterrupt):
        os.killpg(process.pid, signal.SIGINT)
        process.wait(timeout=30)
    code = int(result.read_text().strip()) if result.exists() else 1
    recording = newest_recording(journal_dir, started)
    if recording is not None:
        print(f"rosmc_demo: mission recording: {recording}", flush=True)
    print(f"rosmc_demo: {'completed' if code == 0 else 'FAILED'} in {time.time() - started:.0f} s")
    return code
