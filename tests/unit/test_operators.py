"""The operator allow-list: node names and prefixes, and the sentence a refusal says."""

from __future__ import annotations

import pytest

from rosmc_server.core import NotPermitted
from rosmc_server.core.rules.operators import OperatorAllowList


def test_an_empty_list_lets_every_node_in() -> None:
    allow = OperatorAllowList.of([])
    assert allow.open and allow.allows("/anyone") and allow.allows("")


@pytest.mark.parametrize(
    ("caller", "allowed"),
    [
        ("/station_gui", True),
        ("/station_gui_2", False),  # a name is exact
        ("/ops/console", True),  # "/ops/" is a namespace
        ("/ops", False),
        ("/opsx/console", False),
        ("/rosmc_cli_4711", True),  # "rosmc_cli_*" is a prefix (a leading / is implied)
        ("/unnamed", False),
        ("", False),
    ],
)
def test_names_namespaces_and_prefixes(caller: str, allowed: bool) -> None:
    allow = OperatorAllowList.of("/station_gui, /ops/ rosmc_cli_*")
    assert allow.entries == ("/station_gui", "/ops/", "/rosmc_cli_*")
    assert allow.allows(caller) is allowed


def test_a_refusal_names_the_caller_and_the_list() -> None:
    allow = OperatorAllowList.of(["/station_gui"])
    allow.check("/station_gui", "add_skill")
    with pytest.raises(NotPermitted) as caught:
        allow.check("/test_script", "delete_skills")
    assert str(caught.value) == (
        "node '/test_script' may not call delete_skills: it is not on the mission server's "
        "operator allow-list (~operators: /station_gui)"
    )


@pytest.mark.parametrize("entry", [3, "", " ", "*", None])
def test_an_entry_that_is_no_node_name_is_refused_at_start(entry: object) -> None:
    with pytest.raises(ValueError, match="is not a node name"):
        OperatorAllowList.of([entry])
