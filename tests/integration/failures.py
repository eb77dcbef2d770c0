"""Whether a test's body failed, for fixtures that gather what explains a failure.

``tests/integration/conftest.py`` notes each test's outcome on the test item; a fixture
asks :func:`body_failed` in its teardown (e.g. to have the team's processes print their
stacks, see ``scenario_fixtures.Team.dump_stacks``). Not a test module.
"""

from __future__ import annotations

import pytest

FAILED_CALL = pytest.StashKey[bool]()


def body_failed(request: pytest.FixtureRequest) -> bool:
    """Whether the body of the test that ``request`` belongs to failed."""
    return request.node.stash.get(FAILED_CALL, False)
