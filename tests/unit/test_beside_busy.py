"""tools/beside_busy.py (``make test-busy``): a command runs beside busy processes."""

from __future__ import annotations

import os
import re
import signal
import subprocess
import sys
import textwrap
from pathlib import Path

from tests.conftest import REPO_ROOT, wait_until

TOOL = REPO_ROOT / "tools" / "beside_busy.py"

# Prints the ids of the spinning processes beside it (children of its parent), then exits 7.
COUNT_SPINNERS = textwrap.dedent(
    """
    import os
    from pathlib import Path

    parent = str(os.getppid())
    spinning = []
    for proc in Path("/proc").iterdir():
        try:
            stat = (proc / "stat").read_text().rsplit(")", 1)[1].split()
            cmdline = (proc / "cmdline").read_bytes()
        except (OSError, IndexError):
            continue
        if stat[1] == parent and cmdline.endswith(b"-c\\0while True: pass\\0"):
            spinning.append(int(proc.name))
    print("spinning", sorted(spinning), flush=True)
    raise SystemExit(7)
    """
)


def spinner_pids(output: str) -> list[int]:
    """The busy processes' ids from the tool's first line."""
    match = re.search(r"busy processes \(([\d ]*)\)", output)
    assert match, output
    return [int(pid) for pid in match.group(1).split()]


def gone(pid: int) -> bool:
    """Whether no process ``pid`` runs any more (a zombie counts as gone)."""
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except OSError:
        return True
    return state == "Z"


def test_the_command_runs_beside_the_busy_processes_and_its_status_passes_through() -> None:
    result = subprocess.run(
        [sys.executable, str(TOOL), "--busy", "2", "--", sys.executable, "-c", COUNT_SPINNERS],
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )
    assert result.returncode == 7, result
    pids = spinner_pids(result.stdout)
    assert len(pids) == 2
    assert f"spinning {sorted(pids)}" in result.stdout, result.stdout
    assert all(gone(pid) for pid in pids), pids


def test_the_busy_processes_stop_when_the_tool_is_terminated() -> None:
    runner = subprocess.Popen(
        [sys.executable, str(TOOL), "--busy", "2", "--", "sleep", "600"],
        stdout=subprocess.PIPE,
        text=True,
    )
    try:
        assert runner.stdout is not None
        pids = spinner_pids(runner.stdout.readline())
        runner.send_signal(signal.SIGTERM)
        assert runner.wait(timeout=60) == 130
        wait_until(lambda: all(gone(pid) for pid in pids), 60.0, "the busy processes stop")
    finally:
        if runner.poll() is None:
            os.kill(runner.pid, signal.SIGKILL)
            runner.wait()


def test_a_missing_command_is_refused_in_one_sentence() -> None:
    result = subprocess.run(
        [sys.executable, str(TOOL), "--busy", "2"],
        capture_output=True,
        text=True,
        timeout=60,
        check=False,
    )
    assert result.returncode == 2
    assert "give the command to run after --" in result.stderr
