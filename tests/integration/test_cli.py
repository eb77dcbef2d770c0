"""The ``rosmc`` command line and MissionClient against a real master and mission server.

One mission server runs for the whole module (tests share it and run in file order:
the synchronization test comes late because an upload without a robot never ends).
The CLI runs as subprocesses with the master's environment.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import signal
import socket
import subprocess
import sys
import threading
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import pytest
import rospy
from rosmc.msg import ScienceState

from rosmc_server.cli.parser import build_parser
from rosmc_server.cli.values import parse_vertices, typed_values
from rosmc_server.conversions import library_to_msg
from rosmc_server.conversions.science import science_to_msg
from rosmc_server.core import (
    InvalidRequest,
    MarkerType,
    NotFound,
    Pose,
    RuleViolation,
    TaskMarker,
    load_library,
)
from rosmc_server.core.errors import ServerUnavailable
from rosmc_server.core.views.science import RegionScience, Science
from rosmc_server.interface import SCIENCE_TOPIC
from rosmc_server.ros.client import MissionClient, RevisionConflict, library_from_msg
from rosmc_server.ros.node_setup import init_node
from rosmc_server.text import mission_to_json
from tests.conftest import communicate_or_stacks, wait_until

REPO = Path(__file__).resolve().parents[2]
ROSMC = REPO / "scripts" / "rosmc"
SERVER = REPO / "scripts" / "mission_server"


@dataclass
class Server:
    """The mission server process of this module (restartable)."""

    env: dict[str, str]
    journal_dir: Path
    log_dir: Path
    process: subprocess.Popen[bytes] | None = None
    starts: list[Path] = field(default_factory=list)

    def start(self) -> None:
        """Start the server and wait until it answers."""
        log = self.log_dir / f"mission_server-{len(self.starts)}.log"
        self.starts.append(log)
        with log.open("wb") as out:
            self.process = subprocess.Popen(
                [
                    sys.executable,
                    str(SERVER),
                    f"_journal_dir:={self.journal_dir}",
                    f"_mission_dir:={self.log_dir / 'missions'}",
                ],
                env=self.env,
                cwd=REPO,
                stdin=subprocess.DEVNULL,
                stdout=out,
                stderr=subprocess.STDOUT,
                start_new_session=True,
            )
        with MissionClient(timeout=30.0) as probe:
            probe.get_mission()

    def stop(self, sig: int = signal.SIGINT) -> None:
        """Stop the server (SIGINT lets it unregister; SIGKILL leaves stale registrations)."""
        if self.process is None:
            return
        try:
            os.killpg(self.process.pid, sig)
            self.process.wait(10.0)
        except subprocess.TimeoutExpired:
            os.killpg(self.process.pid, signal.SIGKILL)
            self.process.wait(10.0)
        except ProcessLookupError:
            pass
        self.process = None


@pytest.fixture(scope="module")
def server(ros_master: Any, tmp_path_factory: pytest.TempPathFactory) -> Iterator[Server]:
    """One mission server for the module, journaling into a temporary directory."""
    base = tmp_path_factory.mktemp("cli")
    (base / "journal").mkdir()
    running = Server(dict(ros_master.env), base / "journal", base)
    running.start()
    try:
        yield running
    finally:
        running.stop()
        for log in running.starts:
            print(f"--- {log.name} ---\n{log.read_text(errors='replace')[-3000:]}")


@pytest.fixture(scope="module")
def client(server: Server) -> Iterator[MissionClient]:
    """An in-process client of the module's server."""
    with MissionClient(timeout=30.0) as mission_client:
        yield mission_client


def start_cli(env: dict[str, str], args: Sequence[str]) -> subprocess.Popen[str]:
    """Start ``rosmc ARGS`` (stdout and stderr piped)."""
    return subprocess.Popen(
        [sys.executable, str(ROSMC), *args],
        env=env,
        cwd=REPO,
        stdin=subprocess.DEVNULL,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )


def run_many(env: dict[str, str], commands: Sequence[Sequence[str]]) -> list[Any]:
    """Run independent ``rosmc`` commands in parallel; their CompletedProcess results."""
    started = [(args, start_cli(env, args)) for args in commands]
    results = []
    for args, process in started:
        out, err = process.communicate(timeout=60.0)
        results.append(subprocess.CompletedProcess(args, process.returncode, out, err))
    return results


def rosmc(server: Server, *args: str, code: int = 0) -> str:
    """Run ``rosmc ARGS``; it must exit with ``code``; return its stdout."""
    (result,) = run_many(server.env, [args])
    assert result.returncode == code, f"rosmc {' '.join(args)}: {result.stderr}{result.stdout}"
    return str(result.stdout)


def status(server: Server) -> dict[str, Any]:
    """``rosmc status --json`` as data."""
    data: dict[str, Any] = json.loads(rosmc(server, "status", "--json"))
    return data


def skills_of(data: dict[str, Any], agent: str) -> list[dict[str, Any]]:
    """The skills of ``agent`` in status JSON."""
    return next(a["skills"] for a in data["agents"] if a["name"] == agent)


def assert_refused(result: Any, needle: str) -> None:
    """Exit code 1 and one clear ``rosmc: ...`` line on stderr."""
    assert result.returncode == 1, (result.args, result.stdout, result.stderr)
    assert result.stderr.startswith("rosmc: "), result.stderr
    assert result.stderr.count("\n") == 1, result.stderr
    assert needle in result.stderr, (needle, result.stderr)


@pytest.fixture
def fresh(client: MissionClient) -> MissionClient:
    """An empty mission without task markers."""
    client.get_mission()
    client.new_mission(keep_markers=False)
    return client


def test_library_round_trips_through_the_wire() -> None:
    """What the server sends (library_to_msg) reads back as the same library."""
    shipped = load_library(REPO / "rosmc_server" / "config" / "mars_team.yaml")
    assert library_from_msg(library_to_msg(shipped)) == shipped


def test_key_value_words_follow_the_schema() -> None:
    """Typed values, marker bindings, unbinding and the @@ escape; clear refusals."""
    library = load_library(REPO / "rosmc_server" / "config" / "mars_team.yaml")
    spec = library.skill("science_rover", "identify_stones")
    values, bindings = typed_values(spec, ["radius=3", "mode=@@quick", "position=@RSS A"])
    assert values == {"radius": 3.0, "mode": "@quick"} and bindings == {"position": "RSS A"}
    assert typed_values(spec, ["position=@"]) == ({}, {"position": None})
    assert typed_values(spec, ["position=1,2"])[0] == {"position": {"x": 1.0, "y": 2.0}}
    with pytest.raises(ValueError, match="expected key=value"):
        typed_values(spec, ["radius"])
    with pytest.raises(NotFound, match="has no parameter 'speed'"):
        typed_values(spec, ["speed=1"])
    with pytest.raises(InvalidRequest, match="given twice"):
        typed_values(spec, ["radius=1", "radius=2"])
    assert parse_vertices("0,0 1,0;0,1", "area")[2] == Pose(0.0, 1.0)
    assert parse_vertices("[{x: 2, y: 3}]", "area") == (Pose(2.0, 3.0),)


def subcommands() -> list[str]:
    """Every subcommand the parser knows (by its own name, not its aliases)."""
    parser = build_parser()
    (action,) = (a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return [name for name, sub in action.choices.items() if sub.prog.endswith(f" {name}")]


def test_help_for_every_subcommand(server: Server) -> None:
    assert {"status", "add", "sync", "unsync", "watch", "library", "marker"} <= set(subcommands())
    commands = [["--help"]] + [[name, "--help"] for name in subcommands()]
    commands += [["marker", action, "--help"] for action in ("add", "move", "rename", "delete")]
    for result in run_many(server.env, commands):
        assert result.returncode == 0, result
        assert result.stdout.startswith(f"usage: rosmc {' '.join(result.args[:-1])}".rstrip())
    usage = run_many(server.env, [["add", "drone"], ["frobnicate"], ["watch", "--count", "0"]])
    assert [result.returncode for result in usage] == [2, 2, 2]


def test_library_as_text_and_json(server: Server) -> None:
    text, data = run_many(server.env, [["library", "drone"], ["--json", "library"]])
    assert text.stdout.startswith("library mars_sample_return\ndrone (dynamic, model drone_scout)")
    assert "    altitude: float = 5 m, range 1..30" in text.stdout
    assert "    target: pose = 0,0,0,0,0,0, marker pose, check on_site" in text.stdout
    assert "science_rover" not in text.stdout
    agents = json.loads(data.stdout)["agents"]
    assert [a["name"] for a in agents][:4] == [
        "drone",
        "science_rover",
        "manipulator_rover",
        "lander",
    ]
    assert agents[3] == {
        "name": "lander",
        "kind": "static",
        "model": "lander",
        "description": "The lander at the origin of the map frame.",
        "skills": [],
    }
    take_off = agents[0]["skills"][0]
    assert take_off["name"] == "take_off"
    assert take_off["parameters"][0] == {
        "name": "altitude",
        "type": "float",
        "default": 5.0,
        "min": 1.0,
        "max": 30.0,
        "choices": [],
        "unit": "m",
        "description": "Height above the ground to climb to.",
        "marker": None,
        "check": None,
    }


AREA = "[{x: 0, y: 0}, {x: 6, y: 0}, {x: 6, y: 6}]"


def run_pair(server: Server, first: Sequence[str], second: Sequence[str]) -> tuple[str, str]:
    """Run two changes at once; both must succeed; their stdout.

    Without --revision a change that loses the race to the other retries once
    against the newer mission, so two concurrent changes both go through.
    """
    one, two = run_many(server.env, [first, second])
    for result in (one, two):
        assert result.returncode == 0, (result.args, result.stderr)
    return one.stdout.strip(), two.stdout.strip()


def test_compose_edit_reorder_barrier(server: Server, fresh: MissionClient) -> None:
    marker, climb = run_pair(
        server,
        ["marker", "add", "RSS A", "position", "10,6"],
        ["add", "drone", "take_off", "altitude=12", "--label=lift", "--retries=2"],
    )
    assert marker == "RSS A"
    cover, go = run_pair(
        server,
        ["add", "drone", "fly_over", f"area={AREA}", "altitude=10", "--index=0"],
        ["add", "manipulator_rover", "navigate_to", "target=3,4,0,0,0,1.57"],
    )
    sci, man = run_pair(
        server,
        ["add", "science_rover", "identify_stones", "position=@RSS A", "mode=detailed"],
        ["add", "manipulator_rover", "identify_stones", "position={x: 10, y: 6}"],
    )
    _, barrier = run_pair(
        server,
        ["edit", climb, "altitude=15", "--label", "climb", "--timeout", "45"],
        ["barrier", sci, man],
    )
    rosmc(server, "reorder", "drone", climb, cover)
    as_json, as_text, markers = run_many(
        server.env, [["status", "--json"], ["status", "--verbose"], ["markers", "--json"]]
    )
    ids = {"climb": climb, "cover": cover, "sci": sci, "man": man, "go": go}

    data = json.loads(as_json.stdout)
    assert data["revision"] == fresh.fetch_mission().revision
    assert data["library"] == "mars_sample_return"
    climb, cover = skills_of(data, "drone")
    assert (climb["id"], cover["id"]) == (ids["climb"], ids["cover"])
    assert climb["label"] == "climb" and climb["params"] == {"altitude": 15.0}
    assert climb["timeout"] == 45.0 and climb["max_retries"] == 2
    assert cover["params"]["area"] == [{"x": 0, "y": 0}, {"x": 6, "y": 0}, {"x": 6, "y": 6}]
    (sci,) = skills_of(data, "science_rover")
    assert sci["bindings"] == {"position": "RSS A"} and sci["params"]["position"]["x"] == 10.0
    assert sci["params"]["mode"] == "detailed"
    by_id = {skill["id"]: skill for skill in skills_of(data, "manipulator_rover")}
    go, man = by_id[ids["go"]], by_id[ids["man"]]  # added concurrently: either order
    assert go["params"]["target"] == {"x": 3, "y": 4, "z": 0, "roll": 0, "pitch": 0, "yaw": 1.57}
    assert man["params"]["position"]["y"] == 6.0 and man["bindings"] == {}
    assert all(s["status"] == "IDLE" and s["transfer"] == "NONE" for s in (climb, sci, go))
    assert data["barriers"] == [
        {"id": barrier, "skills": [sci["id"], man["id"]], "agents": [
            "science_rover", "manipulator_rover"]}
    ]  # fmt: skip
    assert all("link" in agent for agent in data["agents"])
    assert json.loads(markers.stdout) == data["markers"]
    assert [m["name"] for m in data["markers"]] == ["RSS A"]
    text = as_text.stdout
    assert f"barrier {barrier}" in text and "position=@RSS A" in text
    assert text.splitlines()[2].startswith("    link ")

    run_pair(server, ["marker", "move", "RSS A", "8,5"], ["delete-barrier", barrier])
    assert fresh.skill(ids["sci"]).params["position"].x == 8.0  # the bound skill follows
    rosmc(server, "edit", ids["sci"], "position=@")  # unbind, keep the value
    sci_now = fresh.skill(ids["sci"])
    assert sci_now.bindings == {} and sci_now.params["position"].x == 8.0
    assert fresh.get_mission().barriers == ()


def build_mission(client: MissionClient) -> dict[str, str]:
    """A small mission made through the client API; the skill ids by role."""
    client.add_task_marker(TaskMarker("RSS A", MarkerType.POSITION, Pose(10.0, 6.0)))
    return {
        "climb": client.add_skill("drone", "take_off", {"altitude": 12}).skill_id,
        "cover": client.add_skill("drone", "fly_over", {"altitude": 9.5}).skill_id,
        "land": client.add_skill("drone", "land").skill_id,
        "sci": client.add_skill(
            "science_rover", "identify_stones", bindings={"position": "RSS A"}
        ).skill_id,
        "man": client.add_skill("manipulator_rover", "identify_stones").skill_id,
    }


def test_every_error_class_exits_1_with_one_line(
    server: Server, fresh: MissionClient, tmp_path: Path
) -> None:
    broken = tmp_path / "broken.yaml"
    broken.write_text("rosmc_mission: 1\ntasks: []\n")
    fresh.add_task_marker(TaskMarker("RSS A", MarkerType.POSITION, Pose(10.0, 6.0)))
    first = fresh.add_skill("science_rover", "navigate_to").skill_id
    second = fresh.add_skill("science_rover", "explore").skill_id
    cases = {
        ("add", "nobody", "land"): "there is no agent 'nobody'",
        ("add", "lander", "land"): "static agent",
        ("load", str(broken)): "is missing",
        ("add", "drone", "take_off", "altitude=high"): "cannot read 'high' as float",
        ("add", "drone", "fly_over", "area=@RSS A"): "takes area markers",
        ("barrier", first, second): "distinct",
        ("delete", "nope"): "there is no skill 'nope'",
        ("--revision", "1", "add", "drone", "land"): "changed since revision 1",
        ("load", "/nonexistent/mission.yaml"): "cannot read the mission",
    }
    for result, needle in zip(run_many(server.env, list(cases)), cases.values(), strict=True):
        assert_refused(result, needle)
    # 0 would ask for no check at all: the command line takes only a mission's revisions.
    before = fresh.get_mission().revision
    (zero,) = run_many(server.env, [("--revision", "0", "add", "drone", "land")])
    assert zero.returncode == 2 and "must be a mission revision (1 or more)" in zero.stderr
    assert fresh.get_mission().revision == before


def test_client_conflicts_and_local_checks(server: Server, fresh: MissionClient) -> None:
    other = MissionClient(timeout=30.0)
    other.get_mission()
    fresh.add_skill("drone", "land")  # `other` has not seen this
    with pytest.raises(RevisionConflict) as caught:
        other.add_skill("drone", "take_off", {"altitude": 3})
    assert caught.value.current_revision == fresh.revision
    added = other.add_skill("drone", "take_off", {"altitude": 3}, retry_on_conflict=True)
    assert other.revision == added.revision == fresh.revision + 1
    assert other.skill(added.skill_id).params == {"altitude": 3.0}
    with pytest.raises(InvalidRequest):
        other.add_skill("drone", "take_off", {"altitude": "high"})
    with pytest.raises(NotFound):
        other.edit_skill("nope", {"altitude": 3})
    with pytest.raises(InvalidRequest):
        other.add_barrier([added.skill_id, added.skill_id])
    with pytest.raises(RuleViolation):
        other.add_barrier([added.skill_id, fresh.get_mission().task("drone")[0].id])
    other.close()


def test_save_and_load_on_the_servers_host(server: Server, fresh: MissionClient) -> None:
    ids = build_mission(fresh)
    before = mission_to_json(fresh.get_mission())
    target = server.log_dir / "missions" / "team" / "plan.yaml"
    assert not target.parent.exists()  # the server makes the folder
    out = rosmc(server, "save", "--on-server", "team/plan.yaml")
    assert out == f"saved revision {before['revision']} to {target} on the server\n"
    assert target.read_text().startswith("rosmc_mission: 1\n")
    # The JSON answer has no document: it stayed on the server's host.
    assert (
        json.loads(rosmc(server, "--json", "save", "--on-server", "team/plan.yaml"))["document"]
        == ""
    )
    fresh.delete_skills([ids["sci"]])
    rosmc(server, "load", "--on-server", "team/plan.yaml")
    after = mission_to_json(fresh.get_mission())
    assert after["agents"] == before["agents"] and after["revision"] == before["revision"] + 2


def test_save_new_load_restores(server: Server, fresh: MissionClient, tmp_path: Path) -> None:
    ids = build_mission(fresh)
    fresh.add_barrier([ids["sci"], ids["man"]])
    before = mission_to_json(fresh.get_mission())
    path = tmp_path / "mission.yaml"
    assert rosmc(server, "save", str(path)) == f"saved revision {before['revision']} to {path}\n"
    assert path.read_text().startswith("rosmc_mission: 1\n")
    rosmc(server, "new")
    emptied = mission_to_json(fresh.get_mission())
    assert all(agent["skills"] == [] for agent in emptied["agents"])
    assert emptied["markers"] == before["markers"] and emptied["barriers"] == []
    rosmc(server, "load", str(path))
    after = mission_to_json(fresh.get_mission())
    assert after["revision"] == before["revision"] + 2
    assert {key: after[key] for key in ("agents", "barriers", "markers")} == {
        key: before[key] for key in ("agents", "barriers", "markers")
    }


def test_watch_sees_concurrent_changes(server: Server, fresh: MissionClient) -> None:
    watcher = start_cli(server.env, ["watch", "--count", "2"])
    assert watcher.stderr is not None
    ready = watcher.stderr.readline()
    assert ready.startswith("rosmc: watching mission events from revision"), ready
    added = rosmc(server, "add", "drone", "land").strip()
    fresh.get_mission()
    fresh.add_task_marker(TaskMarker("Here", MarkerType.POSITION, Pose(1.0, 2.0)))
    out, err = watcher.communicate(timeout=60.0)
    assert watcher.returncode == 0, err
    first, second = out.splitlines()
    assert "SKILL_ADDED" in first and added in first and "drone" in first
    assert "MARKER_ADDED" in second and "'Here'" in second


def test_watch_misses_no_event_while_it_starts(server: Server, fresh: MissionClient) -> None:
    # Changes stream in while watch starts: it fetches its starting revision only once its
    # subscriber is connected, so it prints every revision after that one, in order.
    stop = threading.Event()

    def flood() -> None:
        for _ in range(2000):  # bounded: stops long before this unless the test hangs
            if stop.is_set():
                return
            fresh.add_skill("drone", "land")

    flooder = threading.Thread(target=flood, daemon=True)
    flooder.start()
    try:
        wait_until(lambda: (fresh.revision or 0) >= 5, 30.0, "the first changes")
        watcher = start_cli(server.env, ["watch", "--json", "--count", "20"])
        out, err = watcher.communicate(timeout=120.0)
    finally:
        stop.set()
        flooder.join(60.0)
    assert watcher.returncode == 0, err
    start = int(re.search(r"from revision (\d+)", err).group(1))  # type: ignore[union-attr]
    revisions = [json.loads(line)["revision"] for line in out.splitlines()]
    assert revisions == list(range(start + 1, start + 21)), (start, revisions)
    assert "not heard" not in err


def test_watch_stops_cleanly_on_ctrl_c(server: Server) -> None:
    watcher = start_cli(server.env, ["watch", "--json", "--states", "0.5"])
    assert watcher.stderr is not None and watcher.stdout is not None
    assert watcher.stderr.readline().startswith("rosmc: watching")
    state = json.loads(watcher.stdout.readline())  # agent states arrive at 2 Hz
    assert state["agent"] == "drone" and "state" in state["state"]
    watcher.send_signal(signal.SIGINT)
    _, err = communicate_or_stacks(watcher)
    assert watcher.returncode == 0, err
    assert "Traceback" not in err


def test_unbarrier_is_delete_barrier(server: Server, fresh: MissionClient) -> None:
    first = fresh.add_skill("science_rover", "explore").skill_id
    second = fresh.add_skill("manipulator_rover", "identify_stones").skill_id
    barrier = fresh.add_barrier([first, second]).barrier_id
    rosmc(server, "unbarrier", barrier)
    assert fresh.get_mission().barriers == ()


def test_undo_walks_back_and_redoes(server: Server, fresh: MissionClient) -> None:
    skill_id = rosmc(server, "add", "drone", "take_off", "altitude=12").strip()
    fresh.get_mission()
    edited = fresh.edit_skill(skill_id, {"altitude": 20.0}).revision
    out = rosmc(server, "undo")  # docs/operator-guide.md, "Undo and redo"
    assert out.startswith(f"revision {edited + 1}: undo of revision {edited} (")
    assert fresh.skill(skill_id).params["altitude"] == 12.0
    rosmc(server, "undo")  # the edit before: the add
    assert fresh.get_mission().task("drone") == []
    rosmc(server, "undo", str(edited + 2))  # undoing that undo redoes the add
    assert fresh.skill(skill_id).params["altitude"] == 12.0
    fresh.get_mission()
    fresh.edit_skill(skill_id, {"altitude": 30.0})
    (refused,) = run_many(server.env, [["undo", str(edited + 1)]])
    assert_refused(refused, f"skill '{skill_id}' was changed since revision {edited + 1}")
    (refused,) = run_many(server.env, [["undo", "1"]])
    assert_refused(refused, "revision 1 is not one of the last")


def test_lost_link_policy_is_checked_and_sent(server: Server) -> None:
    """The robots never answer here: the server sends the policy (exit 0) or refuses it."""
    sent = run_many(
        server.env,
        [
            ["lost-link-policy", "manipulator_rover", "hold", "--after", "5"],
            ["lost-link-policy", "science_rover", "safe_skill", "--skill", "navigate_to", "--param",
             "speed=0.2", "--after", "30"],
            ["--json", "lost-link-policy", "science_rover", "continue"],
            # docs/operator-guide.md, "Lost-link policy"
            ["lost-link-policy", "manipulator_rover", "return_to_link", "--skill", "navigate_to",
             "--when", "idle", "--after", "90"],
            # docs/operator-guide.md, "Command line"
            ["lost-link-policy", "drone", "safe_skill", "--after", "60", "--skill",
             "return_to_lander"],
        ],
    )  # fmt: skip
    assert [result.returncode for result in sent] == [0] * 5, [r.stderr for r in sent]
    assert sent[0].stdout == "manipulator_rover: on link loss: hold after 5 s (sent to the robot)\n"
    assert "run navigate_to after 30 s, then hold" in sent[1].stdout
    assert set(json.loads(sent[2].stdout)) == {"revision"}
    assert sent[3].stdout == (
        "manipulator_rover: on link loss: return to the last link position (navigate_to) "
        "after 90 s idle without a link, then hold (sent to the robot)\n"
    )
    verb = "lost-link-policy"
    refused = {
        (verb, "lander", "hold"): "static agent",
        (verb, "drone", "safe_skill", "--skill", "teleport"): "no skill 'teleport'",
        (verb, "drone", "safe_skill", "--skill", "navigate_to", "--param=speed=99"): "speed",
        (verb, "drone", "return_to_link", "--skill", "land"): "exactly one pose parameter",
    }
    for result, needle in zip(run_many(server.env, list(refused)), refused.values(), strict=True):
        assert_refused(result, needle)
    usage = run_many(
        server.env,
        [
            ["lost-link-policy", "drone", "hold", "--skill", "land"],
            ["lost-link-policy", "drone", "safe_skill"],
            ["lost-link-policy", "drone", "hold", "--param", "speed=1"],
            ["lost-link-policy", "drone", "panic"],
            ["lost-link-policy", "drone", "hold", "--after", "0"],
            ["lost-link-policy", "drone", "return_to_link"],
            ["lost-link-policy", "drone", "hold", "--when", "soon"],
        ],
    )
    assert [result.returncode for result in usage] == [2] * 7, [r.stderr for r in usage]


def test_sync_shows_uploading(server: Server, fresh: MissionClient) -> None:
    ids = build_mission(fresh)
    out = rosmc(server, "sync", "drone", "--upto", ids["cover"])
    assert out.startswith(f"uploading to drone: {ids['climb']}, {ids['cover']} (revision"), out
    data = status(server)
    drone = skills_of(data, "drone")
    assert [s["transfer"] for s in drone] == ["UPLOADING", "UPLOADING", "NONE"], data
    started, refused_edit = run_many(
        server.env, [["start", "drone"], ["edit", ids["climb"], "altitude=3"]]
    )
    # No executor runs in this test: the answer says the start waits for the robot.
    assert started.stdout == (
        "start sent to drone\n"
        "queued for drone: not heard since the server started; "
        "it goes out when the robot first reports\n"
    ), (started.stdout, started.stderr)
    # What waits for the robot, and since when, in the status line and its JSON: the
    # library's default lost-link policy, the upload and the start.
    lines = rosmc(server, "status").splitlines()
    line = lines[lines.index("  drone") + 1]
    assert re.fullmatch(
        r"    link never heard since the server started \(commands wait for it\), "
        r"3 commands waiting for contact \d+ (s|min)",  # the oldest: since the server began
        line,
    ), line
    link = next(a["link"] for a in status(server)["agents"] if a["name"] == "drone")
    assert link["commands_waiting"] == 3 and link["waiting_for"] >= 0.0, link
    fresh.get_mission()
    with pytest.raises(RuleViolation, match="cannot start a new mission while drone holds"):
        fresh.new_mission()
    assert_refused(refused_edit, "being uploaded")
    # No robot ever answers: unsync cancels the upload and the skills are editable again.
    (cancelled,) = run_many(server.env, [["unsync", "drone"]])
    assert cancelled.returncode == 0, (cancelled.stdout, cancelled.stderr)
    drone = skills_of(status(server), "drone")
    assert [s["transfer"] for s in drone] == ["NONE", "NONE", "NONE"], drone


def test_sync_all_sends_every_robot_in_one_change(server: Server, fresh: MissionClient) -> None:
    ids = build_mission(fresh)
    fresh.add_barrier([ids["sci"], ids["man"]])
    before = status(server)
    # One robot's refusal (an unknown stop) sends nobody anything.
    (refused,) = run_many(server.env, [["sync", "--all", "--upto", "nosuch"]])
    assert_refused(refused, "nosuch")
    assert status(server)["revision"] == before["revision"]
    out = rosmc(server, "sync", "--all", "--upto", ids["cover"])
    assert out.splitlines() == [
        f"uploading to drone: {ids['climb']}, {ids['cover']}",
        f"uploading to science_rover: {ids['sci']}",
        f"uploading to manipulator_rover: {ids['man']}",
        f"(revision {before['revision'] + 1})",
        "queued for drone, science_rover, manipulator_rover: not heard since the server "
        "started; it goes out when the robot first reports",
    ], out
    data = status(server)
    assert data["revision"] == before["revision"] + 1  # one change for the whole team
    transfers = {
        a["name"]: [s["transfer"] for s in a["skills"]] for a in data["agents"] if a["skills"]
    }
    assert transfers == {
        "drone": ["UPLOADING", "UPLOADING", "NONE"],
        "science_rover": ["UPLOADING"],
        "manipulator_rover": ["UPLOADING"],
    }, transfers
    # No robot answers here: take every upload back; then send everything, and again back.
    results = run_many(server.env, [["unsync", agent] for agent in transfers])
    assert [r.returncode for r in results] == [0, 0, 0], [r.stderr for r in results]
    out = rosmc(server, "sync", "--all")
    assert out.splitlines()[0] == (
        f"uploading to drone: {ids['climb']}, {ids['cover']}, {ids['land']}"
    ), out
    results = run_many(server.env, [["unsync", agent] for agent in transfers])
    assert [r.returncode for r in results] == [0, 0, 0], [r.stderr for r in results]


def test_status_prints_the_science_score_when_published(
    server: Server, fresh: MissionClient
) -> None:
    init_node("cli_science_publisher")
    publisher = rospy.Publisher(SCIENCE_TOPIC, ScienceState, queue_size=1, latch=True)
    try:
        region = RegionScience("RSS A", 16, 9, 3, 1, 2, "collaborative")
        publisher.publish(science_to_msg(Science(1.0, 1, (region,))))
        lines = rosmc(server, "status").splitlines()
        assert lines[1:3] == [
            "science score 1.00: 1 stone delivered to the lander; regions discovered: RSS A",
            "  RSS A at (16, 9): identified by both rovers, 2 stones left (best 1)",
        ], lines
        science = status(server)["science"]
        assert (science["score"], science["stones_delivered"]) == (1.0, 1), science
        assert science["regions"][0]["identified_by"] == "collaborative", science
    finally:
        publisher.unregister()
    wait_until(lambda: "science score" not in rosmc(server, "status"), 60.0, "no score")
    assert status(server)["science"] is None


def journal_of(server: Server) -> Path:
    """The journal the module's server writes now (the newest in its directory)."""
    return max(server.journal_dir.glob("*.mcap"), key=lambda path: path.stat().st_mtime)


def test_diff_and_restore_a_past_moment(server: Server, fresh: MissionClient) -> None:
    ids = build_mission(fresh)
    barrier = fresh.add_barrier([ids["sci"], ids["man"]]).barrier_id
    planned = mission_to_json(fresh.get_mission())
    fresh.edit_skill(ids["cover"], {"altitude": 4.5})
    fresh.delete_skills([ids["land"]])
    fresh.add_task_marker(TaskMarker("Late", MarkerType.POSITION, Pose(3.0, 4.0)))
    added = fresh.add_skill("drone", "land").skill_id
    now = fresh.revision
    journal = str(journal_of(server))
    text = rosmc(server, "diff", journal, f"r{planned['revision']}", f"r{now}")
    assert text.splitlines()[0].startswith(f"r{planned['revision']} (r{planned['revision']}, ")
    assert f"  {ids['cover']} param altitude: 9.5 -> 4.5\n" in text, text
    assert f"skills removed (1)\n  {ids['land']} (drone land " in text, text
    assert f"skills added (1)\n  {added} (drone land " in text, text
    assert "markers added (1)\n  Late (POSITION)\n" in text, text
    data = json.loads(rosmc(server, "--json", "diff", journal, "0", f"r{now}"))
    assert data["from"]["seconds"] == 0.0 and data["to"]["revision"] == now
    assert {b.split(":")[0] for b in data["barriers_added"]} == {barrier}, data
    assert json.loads(rosmc(server, "--json", "diff", journal, f"r{now}", f"r{now}"))["edits"] == []
    # The live journal has no footer yet: the reader warns on a line of its own first.
    (bad,) = run_many(server.env, [["diff", journal, "soon", "r1"]])
    assert bad.returncode == 1 and "rosmc: cannot read 'soon' as a time" in bad.stderr, bad
    # A robot holding synchronized work: the server refuses and nothing changes.
    rosmc(server, "sync", "drone")
    (refused,) = run_many(server.env, [["restore", journal, "--at", f"r{planned['revision']}"]])
    assert refused.returncode == 1 and "holds unfinished skill" in refused.stderr, refused
    assert fresh.get_mission().revision == fresh.revision
    rosmc(server, "unsync", "drone")
    out = rosmc(server, "restore", journal, "--at", f"r{planned['revision']}")
    assert f"restored {Path(journal).name} at r{planned['revision']} " in out, out
    assert "blueprint of 5 skills" in out and "dropped" not in out, out
    restored = mission_to_json(fresh.get_mission())
    assert {key: restored[key] for key in ("agents", "barriers", "markers")} == {
        key: planned[key] for key in ("agents", "barriers", "markers")
    }


def test_unreachable_master_exits_3_after_the_timeout(server: Server) -> None:
    """No master at ROS_MASTER_URI: exit 3 after --timeout, with one clear line."""
    with socket.socket() as probe:  # a port that nothing listens on
        probe.bind(("127.0.0.1", 0))
        uri = f"http://127.0.0.1:{probe.getsockname()[1]}/"
    (result,) = run_many(dict(server.env, ROS_MASTER_URI=uri), [["--timeout", "1", "status"]])
    assert result.returncode == 3, result
    assert result.stderr == (
        f"rosmc: the ROS master at {uri} is not reachable (is ROS_MASTER_URI right?)\n"
    )


def test_client_reconnects_after_server_restart(server: Server, client: MissionClient) -> None:
    client.get_mission()
    server.stop(signal.SIGKILL)  # connections break, the registrations stay behind
    with pytest.raises(ServerUnavailable):  # after its timeout, not a hang
        MissionClient(timeout=1.0).get_mission()
    server.start()  # a new mission at revision 1 (never 0: no check), in a new journal
    assert client.get_mission().revision == 1  # the broken connection was replaced
    assert client.add_skill("drone", "land").revision == 2
    server.stop()  # cleanly: the services are gone, the master stays
    (result,) = run_many(server.env, [["--timeout", "1", "add", "drone", "land"]])
    assert result.returncode == 3
    assert result.stderr.startswith("rosmc: the mission server is not reachable"), result.stderr
