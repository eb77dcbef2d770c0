"""Which figures of a benchmark's JSON make its headline table (used by run_all.py).

A benchmark's JSON is flattened to dotted keys (``sizes.20x500.latency.add.p50``). Its
headline rows are the keys matching the glob patterns listed for it in :data:`HEADLINES`
(every one of them: the list is the choice), or, for a benchmark not listed, the keys whose
last part looks like a figure (percentiles, maxima, sizes, rates, memory), at most
:data:`MAX_ROWS` of them. A benchmark listed in
:data:`CURVES` is shown as its own table instead (``scale``: operations x mission sizes).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from fnmatch import fnmatchcase
from typing import Any

MAX_ROWS = 40

# Names that label the items of a list of results better than their index.
LIST_LABELS = ("name", "size", "label", "skills", "robots", "agents")

DEFAULT_PATTERNS = (
    "*p50*",
    "*p95*",
    "*median*",
    "*.max",
    "*max_ms",
    "*rtf",
    "*rss*",
    "*bytes*",
    "*ratio*",
    "*score",
    "*_per_*",
)

# Never headlines: the targets a benchmark prints beside its figures, sample counts.
EXCLUDED_PATTERNS = ("target*", "*.target*", "*.n", "*samples*")

HEADLINES: dict[str, tuple[str, ...]] = {
    "server": (
        "sizes.20x500.latency.*.p50_ms",
        "sizes.20x500.latency.*.p95_ms",
        "sizes.*.event_bytes.add",
        "sizes.20x500.event_bytes.*",
        "sizes.*.snapshot_bytes",
        "sizes.*.journal_bytes_per_change",
        "sizes.*.server_peak_rss_mib",
        # The whole-mission paths at the largest size, and the CPU a snapshot subscriber costs.
        "sizes.20x500.whole.get_mission_*.p50_ms",
        "sizes.20x500.whole.save_*.p50_ms",
        "sizes.20x500.whole.load_saved_document*.p50_ms",
        "sizes.20x500.whole.load_server_*_ms",
        "sizes.*.snapshot_subscriber.*share*",
    ),
    "journal": (
        "append.*.p50_us",
        "append.*.p95_us",
        "append.chunked.bytes_per_event",
        "recovery.*_ms",
        "snapshot_20x500.*bytes",
        "memory.retained_bytes_per_change",
        "damage.*.resumed_at",
        "damage.*.events_kept",
        "memory.rss_growth_*_kib",
    ),
    "executor": ("*sync_to_start*median_ms", "*barrier_skew*median_ms", "*barrier_skew*max_ms"),
    "outage": (
        "refused",
        "contact_to_delivery.p50_ms",
        "contact_to_delivery.p95_ms",
        "max_waiting_per_robot",
    ),
    "sim": ("*.rtf", "*cpu_share"),
    "demo": ("runs.*.score", "runs.*.mission_sim_s", "runs.*.mission_wall_s"),
    "multihost": (
        "*.sync_to_start.robot_running_after_return.median_ms",
        "*.sync_to_start.operator_sees_running_after_return.median_ms",
        "*.barrier_skew.median_ms",
        "*.barrier_skew.max_ms",
        "radio_cuts.*.started_during_cut",
        "radio_cuts.*.restore_to_first_start.median_ms",
        "radio_cuts.*.restore_to_last_start.median_ms",
        "radio_cuts.*.restore_to_last_start.max_ms",
        "idle_radio.*.uplink_bytes_per_s",
    ),
    "idle_link": (
        "skills_on_robot",
        "uplink_kbit_per_s",
        "uplink_bytes_per_s",
        "downlink_bytes_per_s",
        "uplink_by_kind.*.bytes_per_s",
    ),
    "command_gui_start": (
        "sizes.*.first_rows_s",
        "sizes.*.all_rows_s",
        "sizes.*.floor_s",
        "sizes.*.overhead_over_floor_s",
        "sizes.*.decode_ms",
    ),
    "change_bytes": (
        "sizes.*.now.bytes_per_change./rosmc/mission*",
        "sizes.*.broadcast.bytes_per_change./rosmc/mission",
        "sizes.*.now.late_joiner_snapshot_bytes",
    ),
}


@dataclass(frozen=True)
class Figure:
    """One row of a headline table."""

    label: str
    value: str


def flatten(value: Any, prefix: str = "") -> dict[str, Any]:
    """Every leaf of a JSON value under its dotted key."""
    if isinstance(value, dict):
        items = list(value.items())
    elif isinstance(value, list) and value and all(isinstance(v, dict) for v in value):
        items = [(_list_label(item, index), item) for index, item in enumerate(value)]
    else:
        return {prefix: value} if prefix else {"value": value}
    flat: dict[str, Any] = {}
    for key, item in items:
        flat.update(flatten(item, f"{prefix}.{key}" if prefix else str(key)))
    return flat


def headline_rows(name: str, flat: dict[str, Any]) -> list[Figure]:
    """The headline figures of benchmark ``name`` from its flattened JSON."""
    patterns = HEADLINES.get(name, DEFAULT_PATTERNS)
    if name in HEADLINES:
        keys = [k for p in patterns for k in flat if fnmatchcase(k, p)]
        limit = len(keys)
    else:
        keys = [k for k in flat if any(fnmatchcase(k, p) for p in patterns)]
        limit = MAX_ROWS
    unique = list(
        dict.fromkeys(
            k
            for k in keys
            if _is_figure(flat[k]) and not any(fnmatchcase(k, p) for p in EXCLUDED_PATTERNS)
        )
    )
    return [Figure(key, _format(flat[key])) for key in unique[:limit]]


def _list_label(item: dict[str, Any], index: int) -> str:
    if "agents" in item and "skills_per_agent" in item:
        return f"{item['agents']}x{item['skills_per_agent']}"
    for key in LIST_LABELS:
        if isinstance(item.get(key), (str, int)):
            return f"{key}={item[key]}"
    return str(index)


def _is_figure(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def _format(value: float) -> str:
    if isinstance(value, int) or float(value).is_integer():
        return f"{int(value):,}"
    if abs(value) >= 100:
        return f"{value:,.0f}"
    return f"{value:.3g}"


def scale_curves(figures: dict[str, Any]) -> list[str]:
    """bench_scale.py's figures as Markdown: per operation, p50 (p95) ms at each size."""
    sizes = {int(n): size for n, size in figures.get("sizes", {}).items() if "latency" in size}
    if not sizes:
        return []
    order = sorted(sizes)
    ratio = next((v for k, v in figures.items() if k.startswith("ratio_p50_")), {})
    names = list(dict.fromkeys(n for size in sizes.values() for n in size["latency"]))
    head = ["operation", *(f"{n:,}" for n in order), "p50 ratio", "event bytes"]
    lines = [
        f"p50 (p95) ms per mission size in skills (2 robots); ratio = p50 at the largest over "
        f"p50 at 100, target <= {figures.get('target_ratio', 1.5)}; event bytes at the "
        "smallest / largest size.",
        "",
        "| " + " | ".join(head) + " |",
        "|" + " --- |" * len(head),
    ]
    for name in names:
        cells = []
        for n in order:
            got = sizes[n]["latency"].get(name)
            cells.append(_p50_p95(got) if got else "")
        event = [sizes[n].get("event_bytes", {}).get(name) for n in (order[0], order[-1])]
        shown = " / ".join(f"{b:,}" for b in event) if None not in event else ""
        lines.append(f"| {name} | " + " | ".join([*cells, str(ratio.get(name, "")), shown]) + " |")
    spaced = [
        f"{int(n):,}: {_p50_p95(size['spaced_edit'])}"
        for n, size in sorted(figures.get("sizes", {}).items(), key=lambda item: int(item[0]))
        if "spaced_edit" in size
    ]
    if spaced:
        lines += ["", "Edits 60 ms apart, p50 (p95) ms at " + ", ".join(spaced) + "."]
    if figures.get("over_target"):
        lines += ["", "Over the ratio target: " + ", ".join(figures["over_target"]) + "."]
    return lines


def _p50_p95(figure: dict[str, float]) -> str:
    return f"{_format(figure['p50_ms'])} ({_format(figure['p95_ms'])})"


CURVES: dict[str, Callable[[dict[str, Any]], list[str]]] = {"scale": scale_curves}
"""Benchmarks shown as their own table (the figures in, Markdown lines out)."""
