#!/usr/bin/env python3
"""Take a screenshot of rviz on a virtual screen, headless.

Starts ``Xvfb`` on a free display (Xvfb picks it itself, ``-displayfd``), starts
``rviz -d CONFIG`` on that display with software OpenGL, polls screenshots of the whole
screen (ImageMagick's ``import -window root``) until rviz has drawn, waits ``--settle``
seconds more so that late messages arrive, writes the last screenshot as a PNG and stops
rviz and Xvfb (their whole process groups: nothing is left behind, also on Ctrl-C or
SIGTERM).

rviz has *drawn* when its 3D view is on screen (the rows and columns mostly of the
config's ``Background Color``), holds at least ``--min-colors`` distinct colours (a bare
grid holds a few dozen, lit markers hundreds) and every ``--expect-color R,G,B`` (e.g. an
unlit marker colour: the data has arrived) covers at least ``--expect-fraction`` of it,
within ``--tolerance`` per channel. rviz under Mesa's software renderer now and then
dies or hangs at start-up (a heap corruption reported by glibc); it is then started
again, up to ``--attempts`` times in all.

``--view NAME`` takes the camera from a saved view of the config (rviz's Views panel)
instead of its current view, through a copy of the config.

The ROS side is the caller's: a master (``ROS_MASTER_URI``) and whatever publishes what
the config shows must be running; rviz waits for the master before it draws.

Example, after ``source env.sh`` with the simulator running
(``roslaunch rosmc sim.launch``)::

    python tools/rviz_screenshot.py -o /tmp/sim.png --settle 5

Exit status: 0 when the screenshot was written after rviz had drawn, 1 when rviz did
not draw in time (the last screenshot is still written, to show why), 2 when Xvfb, rviz
or ``import`` cannot run or rviz crashed on every attempt, 130 when interrupted.
"""

from __future__ import annotations

import argparse
import contextlib
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from types import FrameType

import numpy as np
import yaml

REPO_ROOT = Path(__file__).resolve().parents[1]
DEFAULT_CONFIG = REPO_ROOT / "rviz" / "sim.rviz"
DEFAULT_SIZE = (1600, 1000)
XVFB_START_TIMEOUT = 10.0
GRAB_TIMEOUT = 20.0
STOP_TIMEOUT = 5.0
POLL_PERIOD = 0.5

RGB = tuple[int, int, int]


CHROME_LEVEL = 200  # rviz's panels and bars: every channel lighter than this


def _area(box: tuple[int, int, int, int]) -> int:
    top, bottom, left, right = box
    return (bottom - top + 1) * (right - left + 1)


def _longest_run(indices: np.ndarray) -> np.ndarray:
    """The longest run of consecutive numbers in sorted ``indices``."""
    breaks = np.flatnonzero(np.diff(indices) != 1) + 1
    runs = np.split(indices, breaks)
    return max(runs, key=len)


class ScreenshotError(RuntimeError):
    """A program the tool needs is missing or failed."""


@dataclass(frozen=True)
class Screenshot:
    """One screenshot (or a part of one): a ``height x width x 3`` uint8 RGB array."""

    pixels: np.ndarray

    @property
    def width(self) -> int:
        """Width in pixels."""
        return int(self.pixels.shape[1])

    @property
    def height(self) -> int:
        """Height in pixels."""
        return int(self.pixels.shape[0])

    def distinct_colors(self) -> int:
        """How many different RGB colours the screenshot holds."""
        flat = self.pixels.reshape(-1, 3).astype(np.uint32)
        packed = (flat[:, 0] << 16) | (flat[:, 1] << 8) | flat[:, 2]
        return int(np.unique(packed).size)

    def near(self, color: RGB, tolerance: int) -> np.ndarray:
        """Which pixels lie within ``tolerance`` of ``color`` in every channel (a bool mask)."""
        difference = np.abs(self.pixels.astype(np.int16) - np.array(color, dtype=np.int16))
        mask: np.ndarray = np.all(difference <= tolerance, axis=2)
        return mask

    def fraction_near(self, color: RGB, tolerance: int) -> float:
        """The fraction of pixels within ``tolerance`` of ``color`` in every channel."""
        return float(self.near(color, tolerance).mean())

    def view(self, background: RGB, tolerance: int = 3) -> Screenshot | None:
        """The 3D view (see :meth:`view_box`), or None."""
        box = self.view_box(background, tolerance)
        if box is None:
            return None
        left, top, width, height = box
        return Screenshot(self.pixels[top : top + height, left : left + width])

    def view_box(self, background: RGB, tolerance: int = 3) -> tuple[int, int, int, int] | None:
        """Left, top, width and height of the 3D view, or None: the rows and columns mostly
        of the ``background`` colour.

        rviz's window around the view (panels, toolbars) never has the view's background
        in more than a few pixels of a row or column; what the view shows (markers, grid)
        covers less than half of it.

        A layer that covers most of the view (the radio-coverage shading) hides the
        background: then the view is where rviz's light window chrome is not, provided
        the background shows in it at all (in a narrow window the shading can fill every
        column of the view, and only the sky beyond the site is background).
        """
        # a window narrower than the screen: the bare screen beside it (pure black) is no
        # part of it, and would thin every row out
        lit_rows = np.flatnonzero(self.pixels.max(axis=(1, 2)) > 0)
        lit_columns = np.flatnonzero(self.pixels.max(axis=(0, 2)) > 0)
        if lit_rows.size == 0:
            return None
        top0, left0 = int(lit_rows[0]), int(lit_columns[0])
        window = self.pixels[top0 : int(lit_rows[-1]) + 1, left0 : int(lit_columns[-1]) + 1]
        if window.shape != self.pixels.shape:
            box = Screenshot(window).view_box(background, tolerance)
            return None if box is None else (box[0] + left0, box[1] + top0, box[2], box[3])
        mask = self.near(background, tolerance)
        by_background = self._box(mask)
        by_chrome = self._dark_box(self.pixels.min(axis=2) <= CHROME_LEVEL)
        if by_chrome is not None:
            top, bottom, left, right = by_chrome
            if not mask[top : bottom + 1, left : right + 1].mean() > 0.01:
                by_chrome = None  # dark, but no background in it: not the 3D view
        if by_background is None and by_chrome is None:
            return None
        box = by_background or by_chrome
        assert box is not None
        if by_chrome is not None and _area(by_chrome) * 0.9 > _area(box):
            box = by_chrome
        top, bottom, left, right = box
        return left, top, right - left + 1, bottom - top + 1

    @staticmethod
    def _dark_box(mask: np.ndarray) -> tuple[int, int, int, int] | None:
        """Top, bottom, left, right of the widest run of columns mostly in ``mask``, and of
        the longest run of rows mostly in it across those columns (panels beside the view
        do not thin its rows out)."""
        columns = np.flatnonzero(mask.mean(axis=0) > 0.5)
        if columns.size == 0:
            return None
        columns = _longest_run(columns)
        left, right = int(columns[0]), int(columns[-1])
        rows = np.flatnonzero(mask[:, left : right + 1].mean(axis=1) > 0.5)
        if rows.size == 0:
            return None
        rows = _longest_run(rows)
        return int(rows[0]), int(rows[-1]), left, right

    @staticmethod
    def _box(mask: np.ndarray, longest: bool = False) -> tuple[int, int, int, int] | None:
        """Top, bottom, left, right of the rows and columns mostly in ``mask`` (``longest``:
        of their longest unbroken run only)."""
        rows = np.flatnonzero(mask.mean(axis=1) > 0.5)
        columns = np.flatnonzero(mask.mean(axis=0) > 0.5)
        if rows.size == 0 or columns.size == 0:
            return None
        if longest:
            rows, columns = _longest_run(rows), _longest_run(columns)
        return int(rows[0]), int(rows[-1]), int(columns[0]), int(columns[-1])

    def ppm(self) -> bytes:
        """The screenshot as a binary PPM."""
        header = f"P6\n{self.width} {self.height}\n255\n".encode()
        return header + np.ascontiguousarray(self.pixels, dtype=np.uint8).tobytes()

    def write_png(self, path: Path) -> None:
        """Write the screenshot as a PNG (through ImageMagick's ``convert``)."""
        path.parent.mkdir(parents=True, exist_ok=True)
        subprocess.run(
            ["convert", "ppm:-", f"png:{path}"],
            input=self.ppm(),
            check=True,
            timeout=GRAB_TIMEOUT,
            stdout=subprocess.DEVNULL,
        )


def parse_ppm(data: bytes) -> Screenshot:
    """A binary PPM (``P6``, 8 bits per channel) as a :class:`Screenshot`."""
    fields: list[bytes] = []
    position = 0
    while len(fields) < 4:  # magic, width, height, maxval; comments start with '#'
        while position < len(data) and data[position : position + 1].isspace():
            position += 1
        if data[position : position + 1] == b"#":
            position = data.index(b"\n", position) + 1
            continue
        end = position
        while end < len(data) and not data[end : end + 1].isspace():
            end += 1
        if end == position:
            raise ValueError("truncated PPM header")
        fields.append(data[position:end])
        position = end
    magic, width, height, maxval = fields[0], int(fields[1]), int(fields[2]), int(fields[3])
    if magic != b"P6" or maxval != 255:
        raise ValueError(f"not an 8-bit binary PPM: {magic!r}, maxval {maxval}")
    body = data[position + 1 : position + 1 + width * height * 3]  # one whitespace byte
    if len(body) != width * height * 3:
        raise ValueError("truncated PPM pixels")
    pixels = np.frombuffer(body, dtype=np.uint8).reshape(height, width, 3)
    return Screenshot(pixels)


def require_programs(*names: str) -> None:
    """Raise :class:`ScreenshotError` naming every program that is not on PATH."""
    missing = [name for name in names if shutil.which(name) is None]
    if missing:
        raise ScreenshotError(f"not installed (make setup installs them): {', '.join(missing)}")


def stop_group(process: subprocess.Popen[bytes], first: signal.Signals) -> None:
    """Stop ``process`` and its process group: ``first``, then SIGTERM, then SIGKILL.

    The process must have been started with ``start_new_session=True``.
    """
    for signum in (first, signal.SIGTERM, signal.SIGKILL):
        if process.poll() is None:
            with contextlib.suppress(ProcessLookupError):
                os.killpg(process.pid, signum)
            with contextlib.suppress(subprocess.TimeoutExpired):
                process.wait(STOP_TIMEOUT)
    # Children that outlived the leader (none expected) go too.
    with contextlib.suppress(ProcessLookupError):
        os.killpg(process.pid, signal.SIGKILL)


@contextlib.contextmanager
def virtual_screen(width: int, height: int) -> Iterator[str]:
    """A running ``Xvfb`` on a display it chose; yields the ``DISPLAY`` value (``:N``)."""
    read_end, write_end = os.pipe()
    process = subprocess.Popen(
        [
            "Xvfb",
            "-displayfd",
            str(write_end),
            "-screen",
            "0",
            f"{width}x{height}x24",
            "-nolisten",
            "tcp",
            "-noreset",
        ],
        pass_fds=(write_end,),
        stdin=subprocess.DEVNULL,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        start_new_session=True,
    )
    os.close(write_end)
    try:
        display = _read_display(read_end, process)
        yield f":{display}"
    finally:
        os.close(read_end)
        stop_group(process, signal.SIGTERM)
        if process.stderr is not None:
            process.stderr.close()


def _read_display(read_end: int, process: subprocess.Popen[bytes]) -> int:
    """The display number Xvfb writes to its ``-displayfd`` once it accepts clients."""
    deadline = time.monotonic() + XVFB_START_TIMEOUT
    text = b""
    os.set_blocking(read_end, False)
    while not text.endswith(b"\n"):
        if process.poll() is not None:
            error = process.stderr.read().decode(errors="replace") if process.stderr else ""
            raise ScreenshotError(f"Xvfb exited {process.returncode}: {error.strip()[-2000:]}")
        if time.monotonic() > deadline:
            raise ScreenshotError("Xvfb did not report a display in time")
        with contextlib.suppress(BlockingIOError):
            chunk = os.read(read_end, 64)
            if not chunk:
                raise ScreenshotError("Xvfb closed -displayfd without a display number")
            text += chunk
            continue
        time.sleep(0.05)
    return int(text.strip())


def grab(display: str) -> Screenshot:
    """A screenshot of the whole screen of ``display``."""
    result = subprocess.run(
        ["import", "-silent", "-window", "root", "-depth", "8", "ppm:-"],
        env={**os.environ, "DISPLAY": display},  # import ignores -display here
        capture_output=True,
        timeout=GRAB_TIMEOUT,
        check=False,
    )
    if result.returncode != 0:
        raise ScreenshotError(f"import failed: {result.stderr.decode(errors='replace').strip()}")
    return parse_ppm(result.stdout)


@dataclass(frozen=True)
class DrawnCheck:
    """When a screenshot counts as drawn (see the module docstring).

    With a ``background`` (the config's), colours are counted in the 3D view only
    (:meth:`Screenshot.view`), so that rviz's panels do not count: their blue display
    names, for one, pass for a marker colour.
    """

    background: RGB | None = None
    min_colors: int = 64
    expect_colors: tuple[RGB, ...] = ()
    expect_fraction: float = 0.0005
    tolerance: int = 24

    def area(self, shot: Screenshot) -> Screenshot | None:
        """The part of ``shot`` that the check looks at (None: no 3D view yet)."""
        return shot if self.background is None else shot.view(self.background)

    def problems(self, shot: Screenshot) -> list[str]:
        """Why ``shot`` does not count as drawn yet (empty: it does)."""
        area = self.area(shot)
        if area is None:
            return [f"no 3D view of background colour {self.background}"]
        where = "the screen" if self.background is None else "the 3D view"
        out = []
        colors = area.distinct_colors()
        if colors < self.min_colors:
            out.append(f"{colors} distinct colours in {where}, fewer than {self.min_colors}")
        for color in self.expect_colors:
            fraction = area.fraction_near(color, self.tolerance)
            if fraction < self.expect_fraction:
                out.append(f"colour {color} covers {fraction:.3%} of {where}")
        return out


def config_background(config: Path) -> RGB | None:
    """The ``Background Color`` of an rviz config (what the 3D view shows where nothing is)."""
    match = re.search(
        r"^\s*Background Color:\s*(\d+);\s*(\d+);\s*(\d+)\s*$", config.read_text(), re.M
    )
    if match is None:
        return None
    red, green, blue = (int(group) for group in match.groups())
    return red, green, blue


def config_window(config: Path) -> tuple[int, int]:
    """The width and height of the window ``config`` asks for (``Window Geometry``), so that
    a screenshot holds rviz as an operator sees it and no empty screen beside it."""
    document = yaml.safe_load(config.read_text())
    geometry = document.get("Window Geometry", {})
    width, height = geometry.get("Width"), geometry.get("Height")
    if not isinstance(width, int) or not isinstance(height, int):
        return DEFAULT_SIZE
    return width, height


def with_saved_view(config: Path, view: str, directory: Path) -> Path:
    """A copy of ``config`` in ``directory`` whose camera is its saved view named ``view``.

    rviz has no command-line option for a saved view (Views panel, "Saved"); the copy
    makes it the current one.

    Raises:
        ScreenshotError: The config has no saved view of that name.
    """
    document = yaml.safe_load(config.read_text())
    views = document.get("Visualization Manager", {}).get("Views", {})
    saved = views.get("Saved") or []
    chosen = next((v for v in saved if isinstance(v, dict) and v.get("Name") == view), None)
    if chosen is None:
        names = ", ".join(repr(v.get("Name")) for v in saved if isinstance(v, dict))
        raise ScreenshotError(f"{config} has no saved view {view!r} (saved: {names or 'none'})")
    views["Current"] = {**chosen, "Name": "Current View"}
    copy = directory / config.name
    copy.write_text(yaml.safe_dump(document, sort_keys=False, default_flow_style=False))
    return copy


def rviz_environment(display: str, base: Mapping[str, str]) -> dict[str, str]:
    """The environment for rviz on ``display``: software OpenGL unless the caller chose."""
    env = dict(base)
    env["DISPLAY"] = display
    env.setdefault("LIBGL_ALWAYS_SOFTWARE", "1")  # Xvfb has no GPU: Mesa's llvmpipe
    env.setdefault("QT_X11_NO_MITSHM", "1")
    env.pop("WAYLAND_DISPLAY", None)
    env.pop("QT_QPA_PLATFORM", None)
    return env


@dataclass(frozen=True)
class Result:
    """What :func:`take_screenshot` produced.

    Attributes:
        shot: The screenshot written to the PNG.
        problems: Why it does not count as drawn (empty: rviz drew).
        display: The X display rviz ran on (gone by the time this is returned).
        attempts: How many times rviz was started.
    """

    shot: Screenshot
    problems: list[str]
    display: str
    attempts: int


def take_screenshot(
    config: Path,
    output: Path,
    *,
    size: tuple[int, int] = DEFAULT_SIZE,
    timeout: float = 45.0,
    settle: float = 3.0,
    attempts: int = 2,
    view: str | None = None,
    check: DrawnCheck | None = None,
    env: Mapping[str, str] | None = None,
    log: Path | None = None,
) -> Result:
    """Screenshot rviz showing ``config`` into ``output`` (PNG).

    Waits up to ``timeout`` seconds for rviz to draw (``check``), then ``settle`` more
    seconds, and writes the screenshot taken then. rviz that crashes or does not draw in
    time is started again, up to ``attempts`` times in all, on the same screen. ``view``
    names a saved view of the config to use as the camera instead of its current one.
    ``log`` receives the output of the last rviz (default: a temporary file, quoted in
    the error when rviz crashes every time).

    Raises:
        ScreenshotError: A program is missing or failed, the config or its saved view is
            missing, or rviz crashed on every attempt.
    """
    require_programs("Xvfb", "rviz", "import", "convert")
    if not config.is_file():
        raise ScreenshotError(f"no rviz config at {config}")
    check = check or DrawnCheck()
    with contextlib.ExitStack() as stack:
        scratch = Path(stack.enter_context(tempfile.TemporaryDirectory(prefix="rviz_")))
        if view is not None:
            config = with_saved_view(config, view, scratch)
        display = stack.enter_context(virtual_screen(*size))
        rviz_env = rviz_environment(display, env or os.environ)
        started = stack.enter_context(
            drawn_rviz(
                config, rviz_env, log or scratch / "log", check, timeout=timeout, attempts=attempts
            )
        )
        shot, problems = started.shot, started.problems
        if not problems and settle > 0:
            time.sleep(settle)
            shot = grab(display)
            problems = check.problems(shot)
        shot.write_png(output)
        return Result(shot=shot, problems=problems, display=display, attempts=started.attempts)
    raise AssertionError("unreachable")  # ExitStack could swallow exceptions, for mypy


@dataclass(frozen=True)
class StartedRviz:
    """What :func:`drawn_rviz` yields.

    Attributes:
        process: The running rviz.
        shot: The screenshot that showed it drawn (or the last one, with ``problems``).
        problems: Why ``shot`` does not count as drawn (empty: rviz drew).
        attempts: How many times rviz was started.
    """

    process: subprocess.Popen[bytes]
    shot: Screenshot
    problems: list[str]
    attempts: int


@contextlib.contextmanager
def drawn_rviz(
    config: Path,
    env: Mapping[str, str],
    log: Path,
    check: DrawnCheck,
    *,
    timeout: float = 45.0,
    attempts: int = 2,
) -> Iterator[StartedRviz]:
    """rviz with ``config`` on ``env["DISPLAY"]``, once it has drawn; stopped afterwards.

    rviz that crashes before it draws, or does not draw within ``timeout`` seconds, is
    started again, up to ``attempts`` times in all; the last one that does not draw in
    time is yielded with its ``problems``. ``log`` receives the output of the last rviz.

    Raises:
        ScreenshotError: rviz crashed on every attempt.
    """
    display = env["DISPLAY"]
    crash = ""
    for attempt in range(1, attempts + 1):
        with running_rviz(config, env, log) as rviz:
            try:
                shot, problems = _wait_until_drawn(display, rviz, check, timeout, log)
            except _RvizCrashed as error:
                crash = str(error)
                continue
            if problems and attempt < attempts:
                continue
            yield StartedRviz(process=rviz, shot=shot, problems=problems, attempts=attempt)
            return
    raise ScreenshotError(f"rviz crashed on all {attempts} attempts; the last:\n{crash}")


class _RvizCrashed(Exception):
    """rviz exited, or reported a fatal error, before it drew."""


# What glibc, Qt or Ogre print when rviz is about to die or hang: e.g. a heap corruption
# ("free(): invalid next size") sometimes leaves rviz hanging instead of aborting.
_FATAL_MARKERS = ("free(): ", "malloc(): ", "double free", "corrupted ", "Segmentation fault")


@contextlib.contextmanager
def running_rviz(
    config: Path, env: Mapping[str, str], log: Path
) -> Iterator[subprocess.Popen[bytes]]:
    """rviz with ``config`` (no splash screen), stopped with its children afterwards."""
    with log.open("wb") as out:
        process = subprocess.Popen(
            ["rviz", "-d", str(config), "--splash-screen", ""],
            env=dict(env),
            stdin=subprocess.DEVNULL,
            stdout=out,
            stderr=subprocess.STDOUT,
            start_new_session=True,
        )
    try:
        yield process
    finally:
        stop_group(process, signal.SIGINT)  # rviz quits cleanly on SIGINT, as on Ctrl-C


def _wait_until_drawn(
    display: str,
    rviz: subprocess.Popen[bytes],
    check: DrawnCheck,
    timeout: float,
    log: Path,
) -> tuple[Screenshot, list[str]]:
    deadline = time.monotonic() + timeout
    while True:
        output = log.read_text(errors="replace")
        if rviz.poll() is not None or any(marker in output for marker in _FATAL_MARKERS):
            tail = "\n".join(output.splitlines()[-30:])
            raise _RvizCrashed(f"rviz (exit status {rviz.poll()}) before drawing:\n{tail}")
        shot = grab(display)
        problems = check.problems(shot)
        if not problems or time.monotonic() > deadline:
            return shot, problems
        time.sleep(POLL_PERIOD)


def _color(text: str) -> RGB:
    try:
        red, green, blue = (int(part) for part in text.split(","))
    except ValueError as error:
        raise argparse.ArgumentTypeError(f"expected R,G,B (0-255), got {text!r}") from error
    if not all(0 <= c <= 255 for c in (red, green, blue)):
        raise argparse.ArgumentTypeError(f"channels must be 0-255: {text!r}")
    return red, green, blue


def _size(text: str) -> tuple[int, int]:
    try:
        width, height = (int(part) for part in text.lower().split("x"))
    except ValueError as error:
        raise argparse.ArgumentTypeError(f"expected WIDTHxHEIGHT, got {text!r}") from error
    return width, height


def _raise_keyboard_interrupt(_signum: int, _frame: FrameType | None) -> None:
    raise KeyboardInterrupt


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point: parse the command line, take the screenshot, report."""
    parser = argparse.ArgumentParser(
        prog="rviz_screenshot",
        description="Screenshot rviz headless: Xvfb on a free display, rviz with a config, "
        "PNG once rviz has drawn. A ROS master and the publishers must be running.",
    )
    parser.add_argument(
        "-c", "--config", type=Path, default=DEFAULT_CONFIG, help="rviz config (rviz/sim.rviz)"
    )
    parser.add_argument("-o", "--output", type=Path, required=True, help="PNG to write")
    parser.add_argument(
        "--size", type=_size, default=DEFAULT_SIZE, help="screen size (default 1600x1000)"
    )
    parser.add_argument(
        "--timeout", type=float, default=45.0, help="wall seconds to wait for rviz to draw (45)"
    )
    parser.add_argument(
        "--settle", type=float, default=3.0, help="wall seconds to wait after it drew (3)"
    )
    parser.add_argument(
        "--attempts", type=int, default=2, help="rviz starts when it crashes or does not draw (2)"
    )
    parser.add_argument(
        "--min-colors",
        type=int,
        default=64,
        help="distinct colours in the 3D view that count as drawn (64)",
    )
    parser.add_argument(
        "--expect-color",
        type=_color,
        action="append",
        default=[],
        metavar="R,G,B",
        help="a colour that must cover --expect-fraction of the 3D view (repeatable)",
    )
    parser.add_argument(
        "--expect-fraction", type=float, default=0.0005, help="of the 3D view (default 0.0005)"
    )
    parser.add_argument("--tolerance", type=int, default=24, help="per channel (default 24)")
    parser.add_argument(
        "--view", help="a saved view of the config to use as the camera (default: its current)"
    )
    parser.add_argument("--log", type=Path, help="write rviz's output to this file")
    args = parser.parse_args(argv)
    config = args.config.resolve()
    background = config_background(config) if config.is_file() else None
    check = DrawnCheck(
        background=background,
        min_colors=args.min_colors,
        expect_colors=tuple(args.expect_color),
        expect_fraction=args.expect_fraction,
        tolerance=args.tolerance,
    )
    signal.signal(signal.SIGTERM, _raise_keyboard_interrupt)  # clean up as on Ctrl-C
    started = time.monotonic()
    try:
        result = take_screenshot(
            config,
            args.output,
            size=args.size,
            timeout=args.timeout,
            settle=args.settle,
            attempts=args.attempts,
            view=args.view,
            check=check,
            log=args.log,
        )
    except ScreenshotError as error:
        print(f"rviz_screenshot: {error}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("rviz_screenshot: interrupted", file=sys.stderr)
        return 130
    elapsed = time.monotonic() - started
    if result.problems:
        print(
            f"rviz_screenshot: rviz did not draw in {args.timeout:g} s "
            f"({'; '.join(result.problems)}); last screenshot in {args.output}",
            file=sys.stderr,
        )
        return 1
    shot = result.shot
    print(
        f"rviz_screenshot: {args.output} ({shot.width}x{shot.height}, "
        f"{shot.distinct_colors()} colours) in {elapsed:.1f} s on display {result.display}, "
        f"rviz started {result.attempts} time(s)"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
