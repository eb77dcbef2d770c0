"""Run every benchmark in bench/ and collect its figures: ``make bench``.

Each ``bench/bench_*.py`` prints one JSON object. This runs them one after another (each in
its own process group; one that overruns gets SIGTERM, then SIGKILL), then writes

* ``bench/results.json``: the machine it ran on, and per benchmark its wall time, exit code
  and figures;
* ``bench/results.md``: the headline figures as Markdown tables, the same text that
  ``--docs`` puts into docs/performance.md between the ``bench:begin`` / ``bench:end`` markers.

Usage::

    python bench/run_all.py [--only server,scale] [--timeout 900] [--docs]

A benchmark that fails or prints no JSON is recorded with its exit code and the tail of its
output; the run goes on with the next one and exits 1 at the end. One that cannot run here
prints ``{"skipped": reason}`` (``bench_multihost.py`` needs root); the tables say so.
"""

from __future__ import annotations

import argparse
import datetime
import json
import os
import platform
import signal
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

from headlines import CURVES, flatten, headline_rows

BENCH_DIR = Path(__file__).resolve().parent
REPO = BENCH_DIR.parent
PERFORMANCE_DOC = REPO / "docs" / "performance.md"
BEGIN, END = "<!-- bench:begin -->", "<!-- bench:end -->"
TERM_GRACE = 60.0  # seconds a benchmark stopped for its timeout has to print and clean up


def machine() -> dict[str, Any]:
    """What the figures were measured on."""
    cpu = ""
    cpuinfo = Path("/proc/cpuinfo")
    if cpuinfo.exists():
        for line in cpuinfo.read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    memory_kib = 0
    meminfo = Path("/proc/meminfo")
    if meminfo.exists():
        memory_kib = int(meminfo.read_text().split()[1])
    commit = subprocess.run(
        ["git", "-C", str(REPO), "rev-parse", "--short", "HEAD"],
        capture_output=True,
        text=True,
        check=False,
    ).stdout.strip()
    return {
        "cpu": cpu,
        "cores": os.cpu_count(),
        "memory_gib": round(memory_kib / 2**20, 1),
        "kernel": platform.release(),
        "python": platform.python_version(),
        "commit": commit,
        "date": datetime.datetime.now(datetime.UTC).strftime("%Y-%m-%d %H:%M UTC"),
    }


def last_json(text: str) -> Any:
    """The last JSON object printed at the start of a line in ``text`` (None if none)."""
    decoder = json.JSONDecoder()
    found = None
    position = 0
    while (start := text.find("{", position)) >= 0:
        if start == 0 or text[start - 1] == "\n":
            try:
                found, end = decoder.raw_decode(text, start)
                position = end
                continue
            except json.JSONDecodeError:
                pass
        position = start + 1
    return found


def run_one(script: Path, timeout: float) -> dict[str, Any]:
    """Run one benchmark; its figures, wall time, exit code, the machine's load (and output
    tail on failure).

    The load average (1 min) is taken before and after: the machines are shared, and a
    figure measured beside other work is only comparable with that said next to it.
    """
    load_before = os.getloadavg()[0]
    began = time.monotonic()
    process = subprocess.Popen(
        [sys.executable, str(script)],
        cwd=REPO,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        start_new_session=True,  # its masters and nodes go with it on a timeout
    )
    try:
        output, _ = process.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        # SIGTERM first: a benchmark then stops the processes it started and prints the
        # figures it has (see _server_harness.figures_printed); SIGKILL if it does not end.
        os.killpg(process.pid, signal.SIGTERM)
        try:
            output, _ = process.communicate(timeout=TERM_GRACE)
        except subprocess.TimeoutExpired:
            os.killpg(process.pid, signal.SIGKILL)
            output, _ = process.communicate()
        output += f"\n(run_all: stopped after {timeout:.0f} s)"
    figures = last_json(output)
    result: dict[str, Any] = {
        "seconds": round(time.monotonic() - began, 1),
        "returncode": process.returncode,
        "figures": figures,
        "load_average": [round(load_before, 2), round(os.getloadavg()[0], 2)],
    }
    if process.returncode != 0 or figures is None:
        result["output_tail"] = output[-3000:]
    return result


def markdown(results: dict[str, Any]) -> str:
    """The headline figures of ``results`` as Markdown: one table per benchmark."""
    host = results["machine"]
    lines = [
        f"Last `make bench` run: {host['date']}, commit {host['commit']}, {host['cores']} cores "
        f"({host['cpu'] or 'unknown CPU'}), {host['memory_gib']} GiB, Linux {host['kernel']}, "
        f"Python {host['python']}. All figures from `bench/results.json`.",
        "",
    ]
    for name, bench in results["benchmarks"].items():
        commit = bench.get("commit", "?")
        title = f"**{name}** ({bench['seconds']:.0f} s, commit {commit}{_load(bench)})"
        if bench["figures"] is None:
            lines += [f"{title}: failed (exit {bench['returncode']}), no figures.", ""]
            continue
        if isinstance(bench["figures"], dict) and "skipped" in bench["figures"]:
            # e.g. bench_multihost.py without root: say so instead of leaving it out
            lines += [f"{title}: skipped: {bench['figures']['skipped']}", ""]
            continue
        if name in CURVES:
            lines += [title, "", *CURVES[name](bench["figures"]), ""]
            continue
        rows = headline_rows(name, flatten(bench["figures"]))
        if not rows:
            continue
        lines += [title, "", "| figure | value |", "| --- | --- |"]
        lines += [f"| {row.label} | {row.value} |" for row in rows]
        lines.append("")
    return "\n".join(lines).rstrip() + "\n"


def _load(bench: dict[str, Any]) -> str:
    """ ", load average A → B" of a benchmark's run (older results have none)."""
    load = bench.get("load_average")
    return f", load average {load[0]:g} → {load[1]:g}" if load else ""


def update_readme(text: str, table: str) -> str:
    """``text`` with the part between the bench markers replaced by ``table``."""
    if BEGIN not in text or END not in text:
        raise SystemExit(f"docs/performance.md has no {BEGIN} ... {END} markers")
    head, rest = text.split(BEGIN, 1)
    _, tail = rest.split(END, 1)
    return f"{head}{BEGIN}\n{table}{END}{tail}"


def _write_tables(results: dict[str, Any], docs: bool) -> int:
    """Write results.md (and the table in docs/performance.md) from ``results``; print them."""
    table = markdown(results)
    (BENCH_DIR / "results.md").write_text(table)
    if docs:
        PERFORMANCE_DOC.write_text(update_readme(PERFORMANCE_DOC.read_text(), table))
    print(table)
    return 0


def main(argv: list[str] | None = None) -> int:
    """Run the benchmarks, write results.json and results.md (and the docs' table with --docs)."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--only", default="", help="comma-separated names, e.g. server,scale")
    parser.add_argument("--timeout", type=float, default=900.0, help="seconds per benchmark")
    parser.add_argument(
        "--docs",
        "--readme",
        dest="docs",
        action="store_true",
        help="also update the table in docs/performance.md",
    )
    parser.add_argument(
        "--render", action="store_true", help="run nothing: redo the tables from results.json"
    )
    args = parser.parse_args(argv)
    if args.render:
        return _write_tables(json.loads((BENCH_DIR / "results.json").read_text()), args.docs)
    wanted = {name.strip() for name in args.only.split(",") if name.strip()}
    scripts = sorted(BENCH_DIR.glob("bench_*.py"))
    if wanted:
        scripts = [s for s in scripts if s.stem.removeprefix("bench_") in wanted]
    results: dict[str, Any] = {"machine": machine(), "benchmarks": {}}
    previous = BENCH_DIR / "results.json"
    if wanted and previous.exists():  # a partial run keeps the other benchmarks' figures
        results["benchmarks"] = json.loads(previous.read_text()).get("benchmarks", {})
    for script in scripts:
        name = script.stem.removeprefix("bench_")
        print(f"run_all: {name} ...", file=sys.stderr, flush=True)
        results["benchmarks"][name] = bench = run_one(script, args.timeout)
        bench["commit"] = results["machine"]["commit"]
        state = "ok" if bench["returncode"] == 0 and bench["figures"] is not None else "FAILED"
        print(f"run_all: {name} {state} in {bench['seconds']:.0f} s", file=sys.stderr, flush=True)
    (BENCH_DIR / "results.json").write_text(json.dumps(results, indent=2) + "\n")
    _write_tables(results, args.docs)
    failed = [n for n, b in results["benchmarks"].items() if b["returncode"] or not b["figures"]]
    if failed:
        print(f"run_all: failed: {', '.join(failed)}", file=sys.stderr)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
