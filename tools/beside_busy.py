"""Run a command with CPU-bound processes beside it; stop them afterwards, whatever happens.

``make test-busy`` runs the test suite this way: the suite must pass on a loaded machine.

    python tools/beside_busy.py [--busy 2] -- make test

The exit status is the command's. The busy processes are stopped when the command ends,
fails, or this script is interrupted (Ctrl-C or SIGTERM).
"""

from __future__ import annotations

import argparse
import signal
import subprocess
import sys
from collections.abc import Sequence
from types import FrameType

# A process that keeps one core busy until it is stopped.
SPIN = "while True: pass"


def _terminated(signum: int, frame: FrameType | None) -> None:
    """SIGTERM ends this script like Ctrl-C does, so its ``finally`` still runs."""
    raise KeyboardInterrupt


def stop(process: subprocess.Popen[bytes]) -> None:
    """Stop ``process`` (SIGKILL if it ignores SIGTERM) and reap it."""
    if process.poll() is None:
        process.terminate()
        try:
            process.wait(timeout=5.0)
        except subprocess.TimeoutExpired:
            process.kill()
            process.wait()


def run_beside_busy(command: Sequence[str], busy: int) -> int:
    """Run ``command`` while ``busy`` processes spin; return its exit status."""
    spinners: list[subprocess.Popen[bytes]] = []
    try:
        for _ in range(busy):
            spinners.append(subprocess.Popen([sys.executable, "-c", SPIN]))
        pids = " ".join(str(p.pid) for p in spinners)
        print(f"beside_busy: {busy} busy processes ({pids}) beside: {' '.join(command)}")
        sys.stdout.flush()
        return subprocess.call(list(command))
    except KeyboardInterrupt:
        return 130
    finally:
        for spinner in spinners:
            stop(spinner)


def main(argv: Sequence[str] | None = None) -> int:
    """Parse ``[--busy N] -- COMMAND...`` and run the command beside N busy processes."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--busy", type=int, default=2, help="CPU-bound processes (default 2)")
    parser.add_argument("command", nargs=argparse.REMAINDER, help="-- then the command")
    args = parser.parse_args(argv)
    command = args.command[1:] if args.command[:1] == ["--"] else args.command
    if not command:
        parser.error("give the command to run after --")
    if args.busy < 0:
        parser.error("--busy must be 0 or more")
    signal.signal(signal.SIGTERM, _terminated)
    return run_beside_busy(command, args.busy)


if __name__ == "__main__":
    sys.exit(main())
