#!/usr/bin/env python3
"""Take a screenshot of the whole operator station on a virtual screen, headless.

Starts ``Xvfb`` (default 1600x1000), a private ``rosmaster`` and ``roslaunch rosmc
operator.launch sim:=true`` on that screen (rviz and the command window as an operator gets
them, each on its own part of the screen), waits until both windows are shown and rviz
has drawn, waits ``--settle`` seconds more and writes the screen as a PNG. Everything it
started is stopped afterwards.

Example, after ``source env.sh``::

    python tools/station_screenshot.py --demo --settle 60 -o docs/station.png
    python tools/station_screenshot.py --team twenty --view "Whole site" --settle 120 \
        -o docs/rviz_twenty.png

The functions here also serve ``tests/integration/test_station_screen.py``.
Exit status: 0 when written, 1 when the station did not come up in time, 130 when
interrupted.
"""

from __future__ import annotations

import argparse
import contextlib
import os
import socket
import subprocess
import sys
import tempfile
import time
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import rviz_screenshot as shots

COMMAND_TITLE = "ROSMC command"
START_TIMEOUT = 180.0


@dataclass(frozen=True)
class Box:
    """A window on the screen: its id, left, top, width and height."""

    window: str
    x: int
    y: int
    width: int
    height: int

    def overlaps(self, other: Box) -> bool:
        """Whether the two windows share a pixel."""
        return (
            self.x < other.x + other.width
            and other.x < self.x + self.width
            and self.y < other.y + other.height
            and other.y < self.y + self.height
        )


def xdotool(display: str, *args: str) -> str:
    """Run xdotool on ``display``; its output ("" when it found nothing)."""
    result = subprocess.run(
        ["xdotool", *args],
        env={**os.environ, "DISPLAY": display},
        capture_output=True,
        text=True,
        timeout=20,
        check=False,
    )
    return result.stdout


def windows(display: str, *search: str) -> list[Box]:
    """The visible windows ``xdotool search --onlyvisible SEARCH`` finds, with their boxes."""
    found = []
    for window in xdotool(display, "search", "--onlyvisible", *search).split():
        shell = dict(
            line.split("=", 1)
            for line in xdotool(display, "getwindowgeometry", "--shell", window).splitlines()
            if "=" in line
        )
        if {"X", "Y", "WIDTH", "HEIGHT"} <= set(shell) and int(shell["WIDTH"]) > 100:
            found.append(
                Box(window, *(int(shell[k]) for k in ("X", "Y", "WIDTH", "HEIGHT")))  # type: ignore[arg-type]
            )
    return found


def command_window(display: str) -> Box | None:
    """The command window, if one is shown."""
    found = windows(display, "--name", f"^{COMMAND_TITLE}")
    return found[0] if found else None


def rviz_window(display: str) -> Box | None:
    """rviz's main window, if one is shown (not its splash screen: 400 px wide)."""
    found = [box for box in windows(display, "--class", "rviz") if box.width > 500]
    return max(found, key=lambda b: b.width * b.height) if found else None


def free_port() -> int:
    """A TCP port nobody listens on now."""
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return int(probe.getsockname()[1])


@dataclass
class Station:
    """A virtual screen, a private master, and the environment to start GUIs on them."""

    display: str
    port: int
    env: Mapping[str, str]
    home: Path

    def launch(
        self, *args: str, log: Path, file: str = "operator.launch"
    ) -> subprocess.Popen[bytes]:
        """``roslaunch rosmc FILE ARGS`` on this master and screen."""
        with log.open("wb") as out:
            return subprocess.Popen(
                ["roslaunch", "-p", str(self.port), "rosmc", file, *args],
                env=dict(self.env),
                cwd=self.home,
                stdout=out,
                stderr=subprocess.STDOUT,
                start_new_session=True,
            )


@contextlib.contextmanager
def station_screen(size: tuple[int, int], home: Path) -> Iterator[Station]:
    """Xvfb of ``size`` and a master of its own on a free port, with ``home`` as ROS_HOME.

    The master is started and stopped here: one that roslaunch started could outlive a
    launch that had to be killed.
    """
    (home / "log").mkdir(parents=True, exist_ok=True)
    with shots.virtual_screen(*size) as display:
        port = free_port()
        env = shots.rviz_environment(display, os.environ)
        env.pop("ROS_HOSTNAME", None)
        env.update(
            ROS_MASTER_URI=f"http://127.0.0.1:{port}/",
            ROS_IP="127.0.0.1",
            ROS_HOME=str(home),
            ROS_LOG_DIR=str(home / "log"),
        )
        with (home / "master.log").open("wb") as log:
            master = subprocess.Popen(
                ["rosmaster", "--core", "-p", str(port)],
                env=env,
                stdout=log,
                stderr=subprocess.STDOUT,
                start_new_session=True,
            )
        try:
            wait_for(lambda: _listening(port), 30.0, "the master")
            yield Station(display, port, env, home)
        finally:
            shots.stop_group(master, shots.signal.SIGTERM)


def _listening(port: int) -> bool:
    with socket.socket() as probe:
        return probe.connect_ex(("127.0.0.1", port)) == 0


def stop(process: subprocess.Popen[bytes]) -> None:
    """End a launch (SIGINT as Ctrl-C, then its whole group)."""
    shots.stop_group(process, shots.signal.SIGINT)


def wait_for(check: object, timeout: float, what: str) -> object:
    """Poll ``check()`` until it returns something true; raise TimeoutError naming ``what``."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        value = check()  # type: ignore[operator]
        if value:
            return value
        time.sleep(0.2)
    raise TimeoutError(f"{what}: not within {timeout:g} s")


def main(argv: Sequence[str] | None = None) -> int:
    """Write the screenshot; returns the exit status."""
    parser = argparse.ArgumentParser(prog="station_screenshot", description=__doc__)
    parser.add_argument("-o", "--output", type=Path, required=True, help="the PNG to write")
    parser.add_argument("--size", type=shots._size, default=shots.DEFAULT_SIZE)
    parser.add_argument("--settle", type=float, default=15.0, help="seconds after both show")
    parser.add_argument("--team", default="three", help="three or twenty (operator.launch)")
    parser.add_argument("--view", help="a saved view of rviz/operator.rviz to look from")
    parser.add_argument(
        "--demo",
        action="store_true",
        help="the scripted demo mission (demo.launch gui:=true) instead of an idle team",
    )
    args = parser.parse_args(argv)
    home = Path(tempfile.mkdtemp(prefix="rosmc_station_"))
    with station_screen(args.size, home) as station:
        log = home / "launch.log"
        journal = f"journal_dir:={home}"  # the mission journal, not into the checkout's bags/
        if args.demo:
            demo = ("gui:=true", "real_time_factor:=2", journal)
            launch = station.launch(*demo, log=log, file="demo.launch")
        else:
            extra = []
            if args.view:
                config = shots.REPO_ROOT / "rviz" / "operator.rviz"
                extra.append(f"rviz_config:={shots.with_saved_view(config, args.view, home)}")
            launch = station.launch("sim:=true", f"team:={args.team}", journal, *extra, log=log)
        try:
            wait_for(
                lambda: command_window(station.display) and rviz_window(station.display),
                START_TIMEOUT,
                "both windows shown",
            )
            time.sleep(args.settle)
            shots.grab(station.display).write_png(args.output)
        except TimeoutError as error:
            print(f"station_screenshot: {error} (log: {home / 'launch.log'})", file=sys.stderr)
            return 1
        finally:
            stop(launch)
    print(f"station_screenshot: {args.output} written")
    return 0


if __name__ == "__main__":
    try:
        sys.exit(main())
    except KeyboardInterrupt:
        sys.exit(130)
