"""The command GUI's requests: typed calls of client methods, checked by mypy.

A request names the method it calls (for the message area and the undo history) and keeps
its arguments; mypy refuses, where a widget builds the request, an unknown method or
arguments the method does not take. The type check runs on small files in ``tmp_path``.
"""

from __future__ import annotations

import subprocess
import sys
import textwrap
from pathlib import Path

from rosmc_rqt_command.core.requests import Answer, ask
from tests.unit.layering_rules import REPO


def test_a_request_names_its_method_and_keeps_its_arguments() -> None:
    seen: list[Answer] = []
    request = ask(lambda c: c.unsynchronize, "take back", 7, seen.append)("alpha", None)
    assert request.operation == "unsynchronize"
    assert (request.args, dict(request.kwargs)) == (("alpha", None), {})
    assert (request.what, request.seen, request.on_answer) == ("take back", 7, seen.append)


def type_errors(tmp_path: Path, body: str) -> list[str]:
    """mypy's errors for a module that builds requests (one line each)."""
    source = tmp_path / "uses_requests.py"
    source.write_text(
        "from rosmc_rqt_command.core.requests import ask\n" + textwrap.dedent(body),
        encoding="utf-8",
    )
    result = subprocess.run(
        [sys.executable, "-m", "mypy", "--strict", "--no-error-summary", str(source)],
        cwd=REPO,
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
        env={"MYPYPATH": str(REPO), "PATH": "/usr/bin:/bin"},
    )
    return [line for line in result.stdout.splitlines() if ": error:" in line]


def test_mypy_refuses_a_wrong_call_and_accepts_a_right_one(tmp_path: Path) -> None:
    wrong = type_errors(
        tmp_path,
        """
        ask(lambda c: c.delete_skills, "delete", 3)(42)
        ask(lambda c: c.retry_skill, "retry", 3)("a", "b")
        ask(lambda c: c.no_such_method, "?", 3)()
        """,
    )
    assert {int(line.split(":")[1]) for line in wrong} == {3, 4, 5}, wrong  # line 2 is blank
    right = type_errors(
        tmp_path,
        """
        ask(lambda c: c.delete_skills, "delete", 3)(["a-1"])
        ask(lambda c: c.synchronize, "send", 3)("alpha", None)
        ask(lambda c: c.edit_skill, "edit", 3)("a-1", params={"speed": 1.0})
        """,
    )
    assert right == []
