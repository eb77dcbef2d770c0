"""bench/run_all.py and bench/headlines.py: collecting the benchmarks' JSON into tables."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path
from types import ModuleType

import pytest

BENCH = Path(__file__).resolve().parents[2] / "bench"


def load(name: str) -> ModuleType:
    """Import bench/<name>.py (bench/ is a folder of scripts, not a package)."""
    sys.path.insert(0, str(BENCH))
    try:
        spec = importlib.util.spec_from_file_location(f"bench_{name}", BENCH / f"{name}.py")
        assert spec is not None and spec.loader is not None
        module = importlib.util.module_from_spec(spec)
        sys.modules[spec.name] = module  # dataclasses look their module up there
        spec.loader.exec_module(module)
        return module
    finally:
        sys.path.remove(str(BENCH))


run_all = load("run_all")
headlines = load("headlines")


def test_the_last_json_object_printed_is_the_figures() -> None:
    output = 'starting {not json}\n{"a": 1}\nlog line\n{\n  "b": {"c": 2}\n}\n'
    assert run_all.last_json(output) == {"b": {"c": 2}}
    assert run_all.last_json("no figures at all\n") is None


def test_lists_of_results_are_labelled_by_what_they_measured() -> None:
    figures = {"sizes": [{"agents": 2, "skills_per_agent": 10, "latency": {"add": {"p50": 0.4}}}]}
    assert run_all.flatten(figures) == {
        "sizes.2x10.agents": 2,
        "sizes.2x10.skills_per_agent": 10,
        "sizes.2x10.latency.add.p50": 0.4,
    }


def test_headlines_pick_figures_and_leave_targets_out() -> None:
    flat = {"target.p95_ms": 5, "apply.p95_ms": 0.0861, "apply.n": 300, "note": "text"}
    rows = headlines.headline_rows("unlisted", flat)
    assert [(row.label, row.value) for row in rows] == [("apply.p95_ms", "0.0861")]
    flat = {"sizes.20x500.latency.add.p50_ms": 0.37, "sizes.2x10.latency.add.p50_ms": 0.3}
    listed = headlines.headline_rows("server", flat)
    assert [row.label for row in listed] == ["sizes.20x500.latency.add.p50_ms"]


def test_the_readme_table_is_replaced_between_its_markers() -> None:
    text = f"intro\n{run_all.BEGIN}\nold\n{run_all.END}\noutro\n"
    assert run_all.update_readme(text, "new\n") == (
        f"intro\n{run_all.BEGIN}\nnew\n{run_all.END}\noutro\n"
    )
    with pytest.raises(SystemExit, match="markers"):
        run_all.update_readme("no markers", "new\n")


def test_a_failed_benchmark_is_reported_without_figures() -> None:
    results = {
        "machine": run_all.machine(),
        "benchmarks": {"broken": {"seconds": 3.0, "returncode": 1, "figures": None}},
    }
    assert "**broken** (3 s, commit ?): failed (exit 1), no figures." in run_all.markdown(results)


def test_the_scale_benchmark_is_shown_as_operations_by_mission_size() -> None:
    def size(p50: float, bytes_: int) -> dict[str, object]:
        return {
            "latency": {
                "add": {"p50_ms": p50, "p95_ms": p50 * 2, "n": 3},
                "get_mission": {"p50_ms": p50 * 100, "p95_ms": p50 * 200, "n": 3},
            },
            "event_bytes": {"add": bytes_},
            "spaced_edit": {"p50_ms": 0.9, "p95_ms": 2.5, "n": 3},
        }

    figures = {
        "target_ratio": 1.5,
        "sizes": {
            "100": size(0.3, 498),
            "10000": size(0.33, 498),
            "700": {"spaced_edit": {"p50_ms": 1.0, "p95_ms": 3.0}},
        },
        "ratio_p50_10000_vs_100": {"add": 1.1},
        "over_target": [],
    }
    results = {
        "machine": run_all.machine(),
        "benchmarks": {"scale": {"seconds": 60.0, "returncode": 0, "figures": figures}},
    }
    table = run_all.markdown(results)
    assert "| operation | 100 | 10,000 | p50 ratio | event bytes |" in table
    assert "| add | 0.3 (0.6) | 0.33 (0.66) | 1.1 | 498 / 498 |" in table
    assert "| get_mission | 30 (60) | 33 (66) |  |  |" in table
    assert (
        "Edits 60 ms apart, p50 (p95) ms at 100: 0.9 (2.5), 700: 1 (3), 10,000: 0.9 (2.5)." in table
    )
