"""Every shell command the docs show, and how each one is exercised.

The commands are the lines of the ```bash, ```sh and ```console blocks of README.md,
CONTRIBUTING.md and docs/*.md (a console block's ``$ `` lines; comments and line
continuations handled). Each is exercised one of two ways:

* run by ``tests/integration/test_docs_commands.py`` itself when it is cheap
  (:func:`cheap_run`): ``make`` targets as a dry run (``make -n``), ``roslaunch`` files with
  ``roslaunch --nodes`` (every ``name:=value`` checked against the file's ``<arg>``s),
  ``source env.sh``, ``--help``, a unit-test run;
* or listed, verbatim, in :data:`DOC_COMMANDS` with the test that runs it and the text by
  which that test runs it (the command with the test's own ids and paths), which must appear
  in that test function, the test file's module-level code, or a ``tests.*`` module it
  imports.

A command that is neither fails the docs test, saying how to fix it.
"""

from __future__ import annotations

import ast
import re
import shlex
import sys
import xml.etree.ElementTree as ElementTree
from dataclasses import dataclass
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]

SHELL_LANGUAGES = {"bash", "sh", "shell", "console"}
FENCE = re.compile(r"^(?P<indent>\s*)(?P<fence>```+|~~~+)\s*(?P<lang>[\w-]*)")


@dataclass(frozen=True)
class DocCommand:
    """One command as a doc shows it, and where."""

    command: str
    path: str  # relative to the repository
    line: int


def doc_files(repo: Path) -> list[Path]:
    """README.md, CONTRIBUTING.md and every docs/*.md."""
    files = [repo / "README.md", repo / "CONTRIBUTING.md", *sorted((repo / "docs").glob("*.md"))]
    return [path for path in files if path.exists()]


def strip_comment(line: str) -> str:
    """``line`` without a trailing ``# comment`` (a ``#`` outside quotes after a blank)."""
    quote = ""
    for index, char in enumerate(line):
        if quote:
            if char == quote:
                quote = ""
        elif char in "'\"":
            quote = char
        elif char == "#" and (index == 0 or line[index - 1].isspace()):
            return line[:index].rstrip()
    return line.rstrip()


def commands_in(text: str, path: str) -> list[DocCommand]:
    """Every command of the shell blocks of one Markdown text."""
    found: list[DocCommand] = []
    lines = text.splitlines()
    index = 0
    while index < len(lines):
        opening = FENCE.match(lines[index])
        index += 1
        if not opening:
            continue
        fence, lang = opening.group("fence"), opening.group("lang")
        pending, start = "", 0
        while index < len(lines) and not lines[index].strip().startswith(fence):
            raw = lines[index].strip()
            index += 1
            if lang not in SHELL_LANGUAGES:
                continue
            if lang == "console":
                if not raw.startswith("$ ") and not pending:
                    continue  # output
                raw = raw.removeprefix("$ ")
            line = strip_comment(raw)
            if not line and not pending:
                continue
            if not pending:
                start = index
            if line.endswith("\\"):
                pending += line[:-1].rstrip() + " "
                continue
            found.append(DocCommand(pending + line, path, start))
            pending = ""
        index += 1  # the closing fence
    return found


def doc_commands(repo: Path) -> list[DocCommand]:
    """Every command of every doc, in order."""
    return [
        command
        for path in doc_files(repo)
        for command in commands_in(path.read_text(), path.relative_to(repo).as_posix())
    ]


# -- commands the docs test runs itself ------------------------------------------------

SHELL_OPERATORS = ("&&", "||", ";", "|", "$(", "`", ">", "<")


def _plain(command: str) -> list[str] | None:
    """The words of a command without shell operators (a trailing ``&`` dropped), or None."""
    command = command.removesuffix("&").rstrip()
    if any(operator in command for operator in SHELL_OPERATORS):
        return None
    return shlex.split(command)


def cheap_run(command: str) -> list[str] | None:
    """The argv the docs test runs for ``command`` when that is cheap, else None."""
    if command == "source env.sh":
        return ["bash", "-c", "source ./env.sh >/dev/null && command -v rosmc"]
    words = _plain(command)
    if not words:
        return None
    if words[-1] == "--help":
        return words
    if words[0] == "make" and all(not w.startswith("-") for w in words[1:]):
        return ["make", "-n", *words[1:]]
    if words[:2] == ["roslaunch", "rosmc"] and len(words) >= 3:
        return ["roslaunch", "--nodes", *words[1:]]
    if words[:3] == ["python", "-m", "pytest"] and words[3:4] and words[3].startswith("tests/unit"):
        return [sys.executable, *words[1:]]
    return None


def undeclared_launch_args(command: str, launch_dir: Path) -> list[str]:
    """The ``name:=value`` arguments of a ``roslaunch rosmc FILE`` command FILE does not declare."""
    words = _plain(command) or []
    declared = {
        arg.get("name")
        for arg in ElementTree.parse(launch_dir / words[2]).getroot().iter("arg")
        if arg.get("default") is not None or arg.get("value") is None
    }
    given = [word.split(":=", 1)[0] for word in words[3:] if ":=" in word]
    return [name for name in given if name not in declared]


# -- commands other tests run ------------------------------------------------------------


@dataclass(frozen=True)
class Evidence:
    """The test that runs a documented command, and the text by which it runs it."""

    test: str  # "tests/integration/test_x.py::test_y"
    texts: tuple[str, ...]


CLI = "tests/integration/test_cli.py"
BUILD = "tests/integration/test_build.py"
DOCS = "tests/integration/test_docs_commands.py"
MULTIHOST = "tests/integration/test_multihost.py::test_a_mission_across_hosts_survives_a_slow_radio_and_an_outage"  # noqa: E501
ROSTEST = (
    "tests/integration/test_rostest.py::test_rostest_runs_a_file_as_the_docs_show",
    ('"rostest"', '"rosmc"'),
)
# catkin_make run_tests runs `rostest rosmc <file>` for each file add_rostest names.
RUN_TESTS = (
    "tests/integration/test_rostest.py::test_run_tests_runs_the_rostest_file",
    ("TEST_FILES",),
)
CATKIN = f"{BUILD}::test_catkin_make_devel_space"
CATKIN_INSTALL = f"{BUILD}::test_catkin_make_install_space"
CATKIN_TOOLS = f"{BUILD}::test_catkin_build"
ROSDEP = "tests/integration/test_rosdep.py::test_rosdep_install_accepts_the_workspace"
COLCON = f"{BUILD}::test_colcon_build"
REVIEW = f"{DOCS}::test_the_review_commands_run_on_the_sample"
REPLAY = f"{DOCS}::test_the_replay_commands_run_against_a_master"
GUI = f"{DOCS}::test_the_command_gui_commands_start_the_window"
RADIO_KEYS = "tests/integration/test_radio_keys.py"
KEYS = f"{RADIO_KEYS}::test_the_key_commands_make_show_and_rotate_a_private_key"


def _cli(test: str, *texts: str) -> Evidence:
    return Evidence(f"{CLI}::{test}", texts)


def _docs(test: str, command: str) -> Evidence:
    return Evidence(test, (command,))


DOC_COMMANDS: dict[str, Evidence] = {
    # docs/operator-guide.md, "Command line"
    "rosmc library": _cli("test_library_as_text_and_json", '["--json", "library"]'),
    "rosmc add drone take_off altitude=8": _cli(
        "test_undo_walks_back_and_redoes", 'rosmc(server, "add", "drone", "take_off", "altitude='
    ),
    "rosmc add science_rover navigate_to target=12,4,0,0,0,1.57": _cli(
        "test_compose_edit_reorder_barrier", '"navigate_to", "target=3,4,0,0,0,1.57"'
    ),
    "rosmc barrier science_rover-1a2b3c manipulator_rover-4d5e6f": _cli(
        "test_compose_edit_reorder_barrier", '["barrier", sci, man]'
    ),
    "rosmc delete-barrier barrier-7a8b9c": _cli(
        "test_compose_edit_reorder_barrier", '["delete-barrier", barrier]'
    ),
    "rosmc undo": _cli("test_undo_walks_back_and_redoes", 'rosmc(server, "undo")'),
    "rosmc sync drone --upto drone-9f8e7d": _cli(
        "test_sync_shows_uploading", 'rosmc(server, "sync", "drone", "--upto", ids["cover"])'
    ),
    "rosmc start drone": _cli("test_sync_shows_uploading", '["start", "drone"]'),
    "rosmc status": _cli("test_sync_shows_uploading", 'rosmc(server, "status")'),
    "rosmc unsync drone": _cli("test_sync_shows_uploading", '[["unsync", "drone"]]'),
    "rosmc lost-link-policy drone safe_skill --after 60 --skill return_to_lander": _cli(
        "test_lost_link_policy_is_checked_and_sent",
        '["lost-link-policy", "drone", "safe_skill", "--after", "60", "--skill"',
    ),
    "rosmc watch": _cli("test_watch_sees_concurrent_changes", '["watch", "--count", "2"]'),
    "rosmc save mission.yaml && rosmc load mission.yaml": _cli(
        "test_save_new_load_restores", 'rosmc(server, "save", str(path))', '"load", str(path)'
    ),
    "rosmc save --on-server team/plan.yaml": _cli(
        "test_save_and_load_on_the_servers_host", '"save", "--on-server", "team/plan.yaml"'
    ),
    "rosmc load --on-server team/plan.yaml": _cli(
        "test_save_and_load_on_the_servers_host", '"load", "--on-server", "team/plan.yaml"'
    ),
    # docs/reference.md, calling a service by hand
    'rosservice call /rosmc/add_skill "{agent: drone, skill: take_off}"': Evidence(
        "tests/integration/test_rosservice_defaults.py::test_add_skill_typed_twice_appends_twice",
        ('"/rosmc/add_skill", request', 'request = "{agent: drone, skill: take_off}"'),
    ),
    # docs/replay.md
    "REC=bags/samples/demo.mcap": _docs(REVIEW, "REC=bags/samples/demo.mcap"),
    "rosmc info $REC": _docs(REVIEW, "rosmc info $REC"),
    "rosmc at $REC 8.5": _docs(REVIEW, "rosmc at $REC 8.5"),
    "rosmc at $REC r80 --json": _docs(REVIEW, "rosmc at $REC r80 --json"),
    "rosmc timeline $REC -o timeline.svg": _docs(REVIEW, "rosmc timeline $REC -o timeline.svg"),
    "rosmc diff $REC r60 0:09": _docs(REVIEW, "rosmc diff $REC r60 0:09"),
    "rosmc tobag $REC mission.bag": _docs(REVIEW, "rosmc tobag $REC mission.bag"),
    "rosbag play --clock -r 20 mission.bag": _docs(REVIEW, "rosbag play --clock -r 20 mission.bag"),
    "rosmc restore $REC --at 9s": _cli(
        "test_diff_and_restore_a_past_moment", 'rosmc(server, "restore", journal, "--at"'
    ),
    "rosmc replay $REC --rate 5": _docs(REPLAY, "rosmc replay $REC --rate 5"),
    "rosmc replay $REC --start 6 --prefix /replay": _docs(
        REPLAY, "rosmc replay $REC --start 6 --prefix /replay"
    ),
    'rosservice call /rosmc/replay/control "{command: 2, time: 8.5}"': _docs(
        REPLAY, 'rosservice call /rosmc/replay/control "{command: 2, time: 8.5}"'
    ),
    'rosservice call /rosmc/replay/control "{command: 0}"': _docs(
        REPLAY, 'rosservice call /rosmc/replay/control "{command: 0}"'
    ),
    "rosmc replay $REC --prefix /replay &": _docs(GUI, "rosmc replay $REC --prefix /replay &"),
    "rosrun rosmc rosmc_command --ns /replay": _docs(
        GUI, "rosrun rosmc rosmc_command --ns /replay"
    ),
    "rosmc_command": _docs(GUI, '"rosmc_command"'),
    "roscore &": _docs(f"{DOCS}::test_roscore_starts_a_master", '"roscore", "-p"'),
    "roscore -p 11311 &": _docs(f"{DOCS}::test_roscore_starts_a_master", '"roscore", "-p"'),
    # docs/integrator-guide.md: nodes, robots on other machines, security
    "rosrun rosmc mission_server _journal:=bags/m.mcap _resume:=true": Evidence(
        "tests/integration/test_server_crash.py::test_kill_9_loses_no_acknowledged_change",
        ('start_server("crash", journal=journal, resume=True)', 'f"_{key}:={_param_text(value)}"'),
    ),
    "export ROS_MASTER_URI=http://10.0.0.1:11311": Evidence(
        MULTIHOST, ("ROS_MASTER_URI=self.master_uri(port)",)
    ),
    "export ROS_IP=10.0.0.11": Evidence(MULTIHOST, ("ROS_IP=self.hosts[host].address",)),
    'rosrun rosmc mission_server _operators:="[/station/, /trusted_operator]"': Evidence(
        "tests/integration/test_trust.py::test_only_nodes_on_the_operator_allow_list_change_the_mission",
        ('start_server(operators="[/station/, /trusted_operator]")',),
    ),
    "ROS_NAMESPACE=/station rosmc add drone take_off": Evidence(
        "tests/integration/test_trust.py::test_only_nodes_on_the_operator_allow_list_change_the_mission",
        ('{**env, "ROS_NAMESPACE": "/station"}, "add", "drone", "take_off"',),
    ),
    # docs/integrator-guide.md, "Building"
    "cmake -S . -B build -DPYTHON_EXECUTABLE=/usr/bin/python3 && make -C build": Evidence(
        f"{BUILD}::test_standalone_cmake_build",
        ('["cmake", "-S", REPO_ROOT, "-B", build', '["make", "-C", build'),
    ),
    "source build/devel/setup.bash": Evidence(
        f"{BUILD}::test_standalone_cmake_build", ('in_workspace(devel / "setup.bash"',)
    ),
    'mkdir -p ~/rosmc_ws/src && ln -s "$PWD" ~/rosmc_ws/src/rosmc': Evidence(
        CATKIN, ('(root / "src").mkdir()', '(root / "src" / "rosmc").symlink_to(REPO_ROOT')
    ),
    "cd ~/rosmc_ws": Evidence(CATKIN, ("cwd=root",)),
    "catkin_make -DPYTHON_EXECUTABLE=/usr/bin/python3": Evidence(
        CATKIN, ('["catkin_make", f"-DPYTHON_EXECUTABLE={SYSTEM_PYTHON}"',)
    ),
    "source devel/setup.bash": Evidence(CATKIN, ('run_in_workspace(devel / "setup.bash"',)),
    "catkin_make install": Evidence(CATKIN_INSTALL, ('["catkin_make", "install"',)),
    "source install/setup.bash": Evidence(CATKIN_INSTALL, ("run_in_workspace(install.setup",)),
    # docs/workspace.md: rosdep (rosdep_offline.sh lists rosdep/sources.sh's sources, then
    # runs rosdep update, against local files: rosdistro is not reachable from CI)
    "src/rosmc/rosdep/sources.sh | sudo tee /etc/ros/rosdep/sources.list.d/30-rosmc.list": (
        Evidence(ROSDEP, ('"rosdep_offline.sh"',))
    ),
    "rosdep update": Evidence(ROSDEP, ('"rosdep_offline.sh"',)),
    "rosdep install --from-paths src --ignore-src -y": Evidence(
        ROSDEP, ('"rosdep", "install"', '["--from-paths", "src", "--ignore-src", "-y"]')
    ),
    "catkin init": Evidence(CATKIN_TOOLS, ('["catkin", "init"]',)),
    "catkin build --cmake-args -DPYTHON_EXECUTABLE=/usr/bin/python3": Evidence(
        CATKIN_TOOLS,
        ('["catkin", "build"', '["--cmake-args", f"-DPYTHON_EXECUTABLE={SYSTEM_PYTHON}"]'),
    ),
    "catkin_make run_tests && catkin_test_results build/test_results": Evidence(
        "tests/integration/test_rostest.py::test_results",
        ('["catkin_make", "run_tests"', '["catkin_test_results"'),
    ),
    "source .venv/bin/activate": Evidence(COLCON, ("colcon = Path(sys.executable).parent",)),
    "mkdir -p ~/rosmc_colcon && cd ~/rosmc_colcon": Evidence(COLCON, ("cwd=root",)),
    "colcon build --base-paths /path/to/rosmc --cmake-args -DPYTHON_EXECUTABLE=/usr/bin/python3": (
        Evidence(COLCON, ('"--base-paths",', '"--cmake-args",'))
    ),
    # docs/writing-skills.md: the example robot, started by the guide's own command
    "PYTHONPATH=$PWD:$PYTHONPATH rosrun rosmc mission_executor __ns:=sweeper1 _agent:=sweeper1 "
    "_skills:=lab_skills:skill_types _library:=sweeper_lab.yaml": Evidence(
        "tests/integration/test_writing_skills_example.py::"
        "test_the_guide_example_robot_runs_its_skill",
        ('blocks("bash")[0]', '["bash", "-c", command]'),
    ),
    # docs/integrator-guide.md, "The radio key"
    "rosmc key new": Evidence(KEYS, ('rosmc("rosmc key new", home)',)),
    "rosmc key show": Evidence(KEYS, ('rosmc("rosmc key show", home)',)),
    "rosmc key new --force": Evidence(KEYS, ('rosmc("rosmc key new --force", home)',)),
    "rostest rosmc server.test": Evidence(*ROSTEST),
    "rostest rosmc executor.test": Evidence(*RUN_TESTS),
    "rostest rosmc sim.test": Evidence(*RUN_TESTS),
    "rostest rosmc markers.test": Evidence(*RUN_TESTS),
}


def unexercised(commands: list[DocCommand], registry: dict[str, Evidence]) -> list[str]:
    """One sentence per command that is neither cheap to run nor in ``registry``."""
    return [
        f"{c.path}:{c.line}: `{c.command}` is shown in the docs but no test runs it: make it "
        f"one the docs test runs itself, or add it verbatim to DOC_COMMANDS in "
        f"tests/integration/doc_commands.py with the test that runs it"
        for c in commands
        if cheap_run(c.command) is None and c.command not in registry
    ]


def _function(tree: ast.Module, name: str) -> ast.FunctionDef | None:
    for node in tree.body:
        if isinstance(node, ast.FunctionDef) and node.name == name:
            return node
    return None


def _searched_text(path: Path, function: ast.FunctionDef, repo: Path) -> str:
    """The test function, the test file's module-level code and the tests.* modules it imports."""
    source = path.read_text()
    tree = ast.parse(source)
    parts = [ast.get_source_segment(source, function) or ""]
    for node in tree.body:
        if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef | ast.ClassDef):
            continue
        parts.append(ast.get_source_segment(source, node) or "")
        if isinstance(node, ast.ImportFrom) and (node.module or "").startswith("tests."):
            helper = repo / Path(*node.module.split(".")).with_suffix(".py")
            if helper.exists():
                parts.append(helper.read_text())
    return "\n".join(parts)


def evidence_problems(registry: dict[str, Evidence], repo: Path) -> list[str]:
    """One sentence per registry entry whose test does not exist or does not run the command."""
    problems = []
    for command, evidence in registry.items():
        file, _, name = evidence.test.partition("::")
        path = repo / file
        function = _function(ast.parse(path.read_text()), name) if path.is_file() else None
        if function is None:
            problems.append(f"`{command}`: its test {evidence.test} does not exist")
            continue
        text = _searched_text(path, function, repo)
        problems += [
            f"`{command}`: {evidence.test} does not contain {wanted!r}"
            for wanted in evidence.texts
            if wanted not in text
        ]
    return problems
