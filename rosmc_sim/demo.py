"""``rosmc_demo``: run the demo mission end to end and report on it.

Starts ``roslaunch rosmc demo.launch`` with its own ROS master on a free
loopback port (so it never disturbs another ROS system on the machine),
streams its output, and exits with the scripted operator's result: 0 when the
mission completed, 1 otherwise (the operator failed, gave up, or never reported).
The mission's MCAP recording stays under ``bags/``.

Headless by default; ``--gui`` also opens rviz (``rviz/operator.rviz``) and the
command GUI on the same mission, so a person can watch and take over; the launch
then stays up after the scripted operator is done, until Ctrl-C.

The end is clean: the operator is not a *required* node here (roslaunch would
report its normal exit as an error); this program waits for the operator's
result file and then shuts roslaunch down itself (SIGINT, as Ctrl-C).
"""

from __future__ import annotations

import argparse
import contextlib
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
        "--gui",
        action="store_true",
        help="also open rviz and the command GUI on the mission (needs a display)",
    )
    parser.add_argument(
        "--journal-dir",
        default=str(PACKAGE_ROOT / "bags"),
        help="where the mission recording goes (default: bags/)",
    )
    parser.add_argument(
        "--snapshot-every",
        type=int,
        default=500,
        metavar="N",
        help="mission events between two full snapshots in the recording (default 500)",
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
        f"snapshot_every:={max(1, args.snapshot_every)}",
        f"timeout:={args.timeout}",
        f"result_file:={result}",
    ]
    command += [f"gui:={str(args.gui).lower()}", "operator_required:=false"]
    if args.gui and not os.environ.get("DISPLAY"):
        print("rosmc_demo: --gui without DISPLAY: rviz and the command GUI cannot open", flush=True)
    started = time.time()
    print(f"rosmc_demo: ROS master on port {port}; recording into {journal_dir}", flush=True)
    process = subprocess.Popen(command, env=env, start_new_session=True)
    code: int | None = None
    try:
        code = wait_for_result(process, result, time.monotonic() + args.timeout + 60)
        if code is not None and args.gui and process.poll() is None:
            print("rosmc_demo: the scripted operator is done; Ctrl-C closes the demo", flush=True)
            process.wait()
    except KeyboardInterrupt:
        pass
    finally:
        stop_launch(process)
    if code is None:
        code = read_result(result)
    recording = newest_recording(journal_dir, started)
    if recording is not None:
        print(f"rosmc_demo: mission recording: {recording}", flush=True)
    outcome = "completed" if code == 0 else "FAILED"
    print(f"rosmc_demo: {outcome} in {time.time() - started:.0f} s", flush=True)
    return 0 if code == 0 else 1


def read_result(path: Path) -> int | None:
    """The operator's exit code from its result file (None: not written, or not yet whole)."""
    try:
        text = path.read_text().strip()
    except FileNotFoundError:
        return None
    try:
        return int(text)
    except ValueError:
        return None


def wait_for_result(process: subprocess.Popen[bytes], path: Path, deadline: float) -> int | None:
    """Wait until the operator wrote its result, roslaunch ended, or ``deadline`` passed."""
    while time.monotonic() < deadline:
        code = read_result(path)
        if code is not None:
            return code
        if process.poll() is not None:
            return read_result(path)
        time.sleep(0.2)
    print("rosmc_demo: timed out", flush=True)
    return None


def stop_launch(process: subprocess.Popen[bytes]) -> None:
    """Shut roslaunch and everything it started down: SIGINT (as Ctrl-C), then harder."""
    for signum, grace in ((signal.SIGINT, 30.0), (signal.SIGTERM, 5.0), (signal.SIGKILL, 5.0)):
        if process.poll() is not None:
            break
        with contextlib.suppress(ProcessLookupError):
            os.killpg(process.pid, signum)
        with contextlib.suppress(subprocess.TimeoutExpired):
            process.wait(timeout=grace)
