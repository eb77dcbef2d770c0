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


def test_the_server_headlines_show_the_whole_mission_paths_and_every_listed_figure() -> None:
    def timing(p50: float) -> dict[str, float]:
        return {"p50_ms": p50, "p95_ms": p50 * 2, "n": 5}

    operations = ("add", "edit", "delete", "reorder", "add_barrier", "marker_move", "sync")
    paths = ("get_mission", "get_mission_wire")
    timed = [f"{path}_{when}" for path in paths for when in ("after_change", "same_revision")]
    timed += ["get_mission_client_decode", "save_to_path", "save_returning_document"]
    timed += ["load_saved_document", "load_saved_document_server_cpu"]
    phases = ("read_and_check", "serialize", "apply_and_journal")
    largest = {  # what bench_server.py prints at 20x500 with --cpu-seconds
        "agents": 20,
        "skills_per_agent": 500,
        "whole": {name: timing(3.0) for name in timed}
        | {f"load_server_{phase}_ms": 70.0 for phase in phases}
        | {"document_bytes": 1500000, "server_peak_rss_after_loads_mib": 110.0},
        "latency": {name: timing(0.4) for name in (*operations, "get_mission")},
        "event_bytes": dict.fromkeys(operations, 400),
        "journal_bytes_per_change": 900,
        "snapshot_subscriber": {
            "cpu_share_without_subscriber": 0.016,
            "cpu_share_with_subscriber": 0.018,
            "subscriber_cost_share": 0.002,
            "snapshots_received": 5,
        },
        "snapshot_bytes": 2700000,
        "server_peak_rss_mib": 110.0,
    }
    smaller = {"agents": 2, "skills_per_agent": 500, "whole": {"save_to_path": timing(1.0)}}
    flat = run_all.flatten({"sizes": [smaller, largest]})
    labels = [row.label for row in headlines.headline_rows("server", flat)]
    assert len(labels) > headlines.MAX_ROWS  # a listed benchmark's patterns are not cut short
    for name in ("get_mission_after_change", "save_to_path", "load_saved_document"):
        assert f"sizes.20x500.whole.{name}.p50_ms" in labels
    assert "sizes.20x500.whole.load_server_serialize_ms" in labels
    assert "sizes.20x500.snapshot_subscriber.subscriber_cost_share" in labels
    assert "sizes.2x500.whole.save_to_path.p50_ms" not in labels  # the largest size only
    assert "sizes.20x500.whole.document_bytes" not in labels
    assert "sizes.20x500.snapshot_subscriber.snapshots_received" not in labels


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


def test_each_benchmark_says_the_load_it_ran_under() -> None:
    results = {
        "machine": run_all.machine(),
        "benchmarks": {
            "busy": {"seconds": 3.0, "returncode": 1, "figures": None, "load_average": [4.5, 6]},
        },
    }
    assert "**busy** (3 s, commit ?, load average 4.5 → 6): failed" in run_all.markdown(results)
