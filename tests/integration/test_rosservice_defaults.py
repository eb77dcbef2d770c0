"""The operator services typed by hand: ``rosservice call`` with only the fields one cares about.

An omitted field arrives as 0 or "": no revision check, a skill appended at the end, the
default lost-link delay. The revision check the GUIs and the Python client rely on (they
send the revision their view was made at) still refuses a stale request. docs/reference.md
gives every field's default.
"""

from __future__ import annotations

import subprocess
from typing import Any

import pytest
import rosmc.msg as wire
import yaml

pytest.register_assert_rewrite("tests.integration.server_fixtures")

from tests.integration.server_fixtures import Client, accepted, skill_ids  # noqa: E402

pytest_plugins = ["tests.integration.server_fixtures"]
pytestmark = pytest.mark.integration


def rosservice_call(env: dict[str, str], service: str, request: str) -> dict[str, Any]:
    """``rosservice call SERVICE REQUEST`` as a person types it; its answer as YAML."""
    done = subprocess.run(
        ["rosservice", "call", service, request],
        env=env,
        capture_output=True,
        text=True,
        timeout=60,
        check=False,
    )
    assert done.returncode == 0, done.stderr
    answer = yaml.safe_load(done.stdout)
    assert isinstance(answer, dict), done.stdout
    return answer


def test_add_skill_typed_twice_appends_twice(fresh: Client, client_node: Any) -> None:
    env = dict(client_node.env)
    request = "{agent: drone, skill: take_off}"
    first = rosservice_call(env, "/rosmc/add_skill", request)
    second = rosservice_call(env, "/rosmc/add_skill", request)
    assert (first["error_code"], first["error"]) == (0, "")
    assert (second["error_code"], second["error"]) == (0, "")
    assert second["revision"] == first["revision"] + 1
    land = rosservice_call(env, "/rosmc/add_skill", "{agent: drone, skill: land}")
    assert land["error_code"] == 0, land
    # Each one at the end of the task, in the order typed.
    order = [first["skill_id"], second["skill_id"], land["skill_id"]]
    assert skill_ids(fresh.mission(), "drone") == order


def test_index_minus_two_inserts_at_the_front(fresh: Client, client_node: Any) -> None:
    env = dict(client_node.env)
    last = rosservice_call(env, "/rosmc/add_skill", "{agent: drone, skill: land}")
    first = rosservice_call(env, "/rosmc/add_skill", "{agent: drone, skill: take_off, index: -2}")
    middle = rosservice_call(env, "/rosmc/add_skill", "{agent: drone, skill: take_off, index: 1}")
    ids = [first["skill_id"], middle["skill_id"], last["skill_id"]]
    assert skill_ids(fresh.mission(), "drone") == ids


def test_the_guis_revision_check_still_refuses_a_stale_view(fresh: Client) -> None:
    seen = fresh.revision()
    accepted(fresh.call("add_skill", base_revision=seen, agent="drone", skill="take_off"))
    # Another operator's change since `seen`: a request made against it is refused.
    stale = fresh.call("add_skill", base_revision=seen, agent="drone", skill="land")
    assert stale.error_code == wire.ErrorCode.CONFLICT, stale
    assert f"revision {seen}" in stale.error
    # -1 and the explicit append of older clients still append.
    now = fresh.revision()
    done = accepted(
        fresh.call("add_skill", base_revision=now, agent="drone", skill="land", index=-1)
    )
    assert skill_ids(fresh.mission(), "drone")[-1] == done.skill_id


def test_a_fresh_server_starts_at_revision_1_so_every_view_is_checked(
    module_server: Any, start_server: Any
) -> None:
    """0 only ever means "no check": no mission is at revision 0, not even a new server's."""
    module_server.stop()  # one server at a time on these service names
    start_server("fresh-start")
    with Client() as client:
        seen = client.revision()
        assert seen == 1, seen
        accepted(client.call("add_skill", base_revision=seen, agent="drone", skill="take_off"))
        # A view of the fresh mission, once another operator changed it, is refused.
        stale = client.call("add_skill", base_revision=seen, agent="drone", skill="land")
        assert stale.error_code == wire.ErrorCode.CONFLICT, stale
        assert len(skill_ids(client.mission(), "drone")) == 1  # the refused one changed nothing


def test_other_services_typed_with_their_defaults(fresh: Client, client_node: Any) -> None:
    env = dict(client_node.env)
    added = rosservice_call(env, "/rosmc/add_task_marker", "{marker: {type: 0}}")
    assert added["error_code"] == 0 and added["name"], added
    skill = rosservice_call(env, "/rosmc/add_skill", "{agent: drone, skill: take_off}")
    edited = rosservice_call(
        env, "/rosmc/edit_skill", f"{{skill_id: {skill['skill_id']}, label: up}}"
    )
    assert edited["error_code"] == 0, edited
    policy = rosservice_call(
        env, "/rosmc/set_lost_link_policy", "{agent: drone, lost_link_policy: hold}"
    )
    assert policy["error_code"] == 0, policy  # after: the default 60 s
    deleted = rosservice_call(env, "/rosmc/delete_skills", f"{{skill_ids: [{skill['skill_id']}]}}")
    assert deleted["error_code"] == 0, deleted
