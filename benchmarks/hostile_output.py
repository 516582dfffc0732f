"""How much output (and time and memory) a hostile robot file makes ar3cli produce.

``--case orphans``: a robot of N links that no joint connects (5,000 by default, and 20,000): S005
reports each extra root, and its message once named every root, so the output grew with N² (5,000
orphans: 170-226 MB of GitHub annotations and step summary; 10,000: 3.5 GB of memory). Each file is
linted by a whole process, ``python -m ar3cli lint-urdf --no-cache --format FMT FILE``, stdout to a
file, ``$GITHUB_STEP_SUMMARY`` set for ``github``; measured per run: wall time, peak memory (the
largest resident set of the process and the children it waited for, ``os.wait4``), bytes written
(stdout plus the step summary). ``--before DIR`` times a second source tree (an older checkout) in
the same rounds, alternating; every process may map at most ``--memory-limit`` MB
(``RLIMIT_AS``) and run ``--timeout`` s: past either it is reported as stopped.

Usage (inside the project's venv)::

    python benchmarks/hostile_output.py --case orphans                      # this checkout, 5 runs
    python benchmarks/hostile_output.py --case orphans --before /path/to/old/checkout --before-runs 1
    python benchmarks/hostile_output.py --case orphans --links 5000 --formats github
"""

from __future__ import annotations

import argparse
import os
import resource
import statistics
import subprocess
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import _timing  # noqa: E402 - after the sys.path line that finds it

CASES = ("orphans",)


def orphans(links: int) -> str:
    """A base link and ``links`` - 1 links that no joint connects (each a second root: S005)."""
    body = "\n".join(f'  <link name="orphan_{index}"/>' for index in range(1, links))
    return f'<?xml version="1.0"?>\n<robot name="orphans">\n  <link name="base"/>\n{body}\n</robot>\n'


@dataclass
class Sample:
    wall: float
    max_rss_mb: float
    output_mb: float
    code: int
    stopped: str = ""


@dataclass
class Row:
    source: str
    case: str
    links: int
    fmt: str
    samples: list[Sample] = field(default_factory=list)


def run(source: Path, robot: Path, fmt: str, memory_mb: int, timeout: float) -> Sample:
    """One whole ``ar3cli lint-urdf`` process on ``robot`` from the source tree ``source``."""
    out, summary = _timing.WORK / "stdout", _timing.WORK / "summary.md"
    summary.write_bytes(b"")
    env = {**_timing.BASE_ENV, "PYTHONPATH": str(source), "AR3CLI_NO_CACHE": "1"}
    env.pop("GITHUB_STEP_SUMMARY", None)
    if fmt == "github":
        env["GITHUB_STEP_SUMMARY"] = str(summary)

    def limit() -> None:
        resource.setrlimit(resource.RLIMIT_AS, (memory_mb << 20, memory_mb << 20))

    with open(out, "wb") as stdout, open(_timing.WORK / "stderr", "wb") as stderr:
        start = time.perf_counter()
        process = subprocess.Popen([sys.executable, "-m", "ar3cli", "lint-urdf", "--no-cache", "--format", fmt,
                                    str(robot)], stdout=stdout, stderr=stderr, stdin=subprocess.DEVNULL,
                                   env=env, cwd=_timing.WORK, preexec_fn=limit)
        stopped = ""
        while True:  # os.wait4, not Popen.wait: the rusage of the process is the point
            pid, status, usage = os.wait4(process.pid, os.WNOHANG)
            if pid:
                break
            if time.perf_counter() - start > timeout:
                process.kill()
                stopped = f"over {timeout:g} s"
                pid, status, usage = os.wait4(process.pid, 0)
                break
            time.sleep(0.02)
        wall = time.perf_counter() - start
    process.returncode = code = os.waitstatus_to_exitcode(status)  # reaped: keep Popen from waiting again
    error = (_timing.WORK / "stderr").read_text(encoding="utf-8", errors="replace")
    if not stopped and (code not in (0, 1) or "MemoryError" in error):
        stopped = f"exit {code}" + (f", over {memory_mb:,} MB" if "Memory" in error or code < 0 else "")
    written = out.stat().st_size + summary.stat().st_size
    return Sample(wall, usage.ru_maxrss / 1024, written / 1e6, code, stopped)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--case", choices=CASES, default="orphans")
    parser.add_argument("--links", type=int, nargs="+", default=[5000, 20000])
    parser.add_argument("--formats", nargs="+", default=["github", "text"])
    parser.add_argument("--runs", type=int, default=5, help="timed runs of this checkout (after one warm-up)")
    parser.add_argument("--before", type=Path, help="a second source tree to time in the same rounds (an older checkout)")
    parser.add_argument("--before-runs", type=int, help="timed runs of --before (default: --runs); an old tree "
                                                        "may take minutes a run")
    parser.add_argument("--memory-limit", type=int, default=4096, help="MB a process may map (RLIMIT_AS)")
    parser.add_argument("--timeout", type=float, default=600, help="seconds a process may run")
    args = parser.parse_args()
    sources = [("this checkout", _timing.REPO, args.runs)]
    if args.before:
        sources.append(("before", args.before.resolve(), args.runs if args.before_runs is None else args.before_runs))
    print(_timing.machine_header(f"hostile_output.py --case {args.case}"))
    print(f"- ar3cli run as `python -m ar3cli lint-urdf --no-cache --format FMT FILE` with PYTHONPATH = the source "
          f"tree; runs: {', '.join(f'{name} {runs}' for name, _, runs in sources)} after one warm-up each, "
          "alternating; medians")
    print("- robot file sizes: " + ", ".join(f"{links:,} links {len(orphans(links)) / 1e3:.0f} KB" for links in args.links))
    print()
    print("| source | case | links | format | runs | wall s | peak memory MB | output KB | exit |")
    print("|---|---|---:|---|---:|---:|---:|---:|---|", flush=True)
    for links in args.links:
        robot = _timing.WORK / f"{args.case}-{links}.urdf"
        robot.write_text(orphans(links))
        for fmt in args.formats:
            variants = [Row(name, args.case, links, fmt) for name, _, _ in sources]
            print(f"  measuring: {links:,} {args.case}, --format {fmt}", file=sys.stderr, flush=True)
            for round_ in range(max(runs for _, _, runs in sources) + 1):  # the first round warms up
                for row, (_, source, runs) in zip(variants, sources):
                    if round_ > runs or (row.samples and row.samples[-1].stopped):
                        continue  # enough runs, or stopped at a limit once: the next run would be too
                    sample = run(source, robot, fmt, args.memory_limit, args.timeout)
                    if round_ or sample.stopped:
                        row.samples.append(sample)
            for row in variants:
                print(_line(row), flush=True)
    print()
    print(_timing.machine_footer())


def _line(row: Row) -> str:
    stopped = next((s.stopped for s in row.samples if s.stopped), "")
    fine = [s for s in row.samples if not s.stopped] or row.samples
    return (f"| {row.source} | {row.case} | {row.links:,} | {row.fmt} | {len(fine)} | "
            f"{statistics.median(s.wall for s in fine):.2f} | {statistics.median(s.max_rss_mb for s in fine):,.0f} | "
            f"{statistics.median(s.output_mb for s in fine) * 1000:,.1f} | {stopped or fine[0].code} |")


if __name__ == "__main__":
    main()
