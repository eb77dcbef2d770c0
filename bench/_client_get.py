"""GetMission as one checkout's own client reads it, timed in a process of its own.

Run by :mod:`bench_perf` with the checkout to measure first on ``sys.path`` (argv[1]), so
that a baseline's figures come from the baseline's client code, not this one's. Against
the running server of ``ROS_MASTER_URI`` it times ``ServiceCaller.call("get_mission")``
(what ``MissionClient`` calls): the first call, calls with nothing changed since the
last, and calls after an edit of one skill (``skill`` argv[2], its float parameter
``param`` argv[3]). ``first_state_ms`` is the first call and the ``MissionState`` that
``MissionClient.fetch_mission`` builds from its answer (what a client waits for before it
can show the mission); ``first_touched_ms`` the first call and a read of every skill's
fields. Prints one JSON object of p50/p95 figures::

    python bench/_client_get.py CHECKOUT SKILL_ID PARAM CALLS
"""

from __future__ import annotations

import json
import statistics
import sys
import time
from typing import Any


def p50_p95(samples: list[float]) -> dict[str, float]:
    """Median and p95 in milliseconds."""
    ordered = sorted(samples)
    p95 = ordered[min(len(ordered) - 1, round(0.95 * (len(ordered) - 1)))]
    return {"p50_ms": round(statistics.median(ordered) * 1000, 3), "p95_ms": round(p95 * 1000, 3)}


def every_field_read(content: Any) -> float:
    """Seconds to read every field of every skill of ``content`` (a reader that built
    skills only when asked for them would build them now)."""
    started = time.perf_counter()
    for task in content.tasks.values():
        for skill in task:
            skill.id, skill.label, skill.params, skill.status, skill.finished  # noqa: B018
    return time.perf_counter() - started


def main(argv: list[str]) -> int:
    """Time the calls; print the figures."""
    checkout, skill_id, param, calls = argv[1], argv[2], argv[3], int(argv[4])
    sys.path.insert(0, checkout)
    import rosmc.msg as wire
    import rospy

    from rosmc_server.core import MissionState
    from rosmc_server.ros.client.connection import ServiceCaller

    rospy.init_node("bench_client_get", anonymous=True, disable_signals=True)
    caller = ServiceCaller(timeout=30.0)
    started = time.perf_counter()
    answer: Any = caller.call("get_mission")
    first = time.perf_counter() - started
    touched = first + every_field_read(answer.content)
    started = time.perf_counter()
    MissionState(answer.content, answer.revision)
    state = first + time.perf_counter() - started
    same, changed = [], []
    for number in range(calls):
        started = time.perf_counter()
        answer = caller.call("get_mission")
        same.append(time.perf_counter() - started)
        value = wire.ParameterValue(name=param, type=wire.ParameterValue.FLOAT)
        value.float_value = 1.0 + number % 7
        caller.call(
            "edit_skill", base_revision=answer.revision, skill_id=skill_id, parameters=[value]
        )
        started = time.perf_counter()
        answer = caller.call("get_mission")
        changed.append(time.perf_counter() - started)
    caller.close()
    figures = {
        "first_ms": round(first * 1000, 3),
        "first_touched_ms": round(touched * 1000, 3),
        "first_state_ms": round(state * 1000, 3),
        "same_revision": p50_p95(same),
        "after_an_edit": p50_p95(changed),
    }
    print(json.dumps(figures))
    rospy.signal_shutdown("done")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
