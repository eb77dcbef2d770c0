#!/usr/bin/env python3
"""Take the docs' picture of the command GUI with the 20-robot team (1600x1000).

Builds the real command widget offscreen, feeds it the staged 20-robot mission of
``tests/team_twenty.py`` (the robots of ``rosmc_sim/scenarios/twenty_robots.yaml``, each with work
on board and planned; one drone failed, two rovers waiting at a barrier, two robots out of
contact) through a real mission and mirror, sets the large-team bar as asked (``--compact``,
``--status failed|waiting|out_of_contact``, ``--filter TEXT``) and writes the picture of
the window. Run after ``source env.sh``::

    python tools/command_gui_team_screenshot.py --compact -o docs/command_gui_team.png

Exit status 0 when written.
"""

from __future__ import annotations

import argparse
import os
import sys
from collections.abc import Sequence
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))
os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")

from python_qt_binding.QtTest import QTest  # noqa: E402

from rosmc_rqt_command.core.team_filter import StatusFilter  # noqa: E402
from tests.team_twenty import stage, twenty_robot_library  # noqa: E402
from tests.unit.conftest import make_mission  # noqa: E402
from tests.unit.test_command_harness import Gui  # noqa: E402


def main(argv: Sequence[str] | None = None) -> int:
    """Stage the team, set the bar and write the picture; the exit status."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("-o", "--output", type=Path, default=REPO / "docs" / "command_gui_team.png")
    parser.add_argument("--size", default="1600x1000", help="window WIDTHxHEIGHT")
    parser.add_argument("--compact", action="store_true", help="compact columns")
    parser.add_argument("--status", default="all", choices=[s.value for s in StatusFilter])
    parser.add_argument("--filter", default="", help="robot name filter text")
    args = parser.parse_args(argv)
    width, height = (int(v) for v in args.size.split("x"))
    library = twenty_robot_library()
    gui = Gui(make_mission(library), library)
    try:
        gui.widget.resize(width, height)
        stage(gui.feed)
        team = gui.widget.team
        team.compact.setChecked(args.compact)
        team.text.setText(args.filter)
        team.status_buttons[StatusFilter(args.status)].click()
        QTest.qWait(500)  # the robots' reports reach the headers, the layout settles
        args.output.parent.mkdir(parents=True, exist_ok=True)
        if not gui.widget.grab().save(str(args.output)):
            print(f"could not write {args.output}", file=sys.stderr)
            return 1
    finally:
        gui.close()
    print(args.output)
    return 0


if __name__ == "__main__":
    sys.exit(main())
