"""Keystroke to diagnostics: how long ``ar3cli server`` takes to answer an edit of a 300-link robot.

A real server process (``ar3cli server --debounce-ms 0``, the console script users run) is driven over
its stdin/stdout by a minimal LSP client in this script: ``initialize``, ``didOpen`` of the robot,
then keystrokes. A keystroke is one ``textDocument/didChange`` that deletes or types back one character
of a joint limit (``upper="1.57"`` -> ``upper="1.5"``, each keystroke another joint), and its time runs from the moment the
message is written until the ``textDocument/publishDiagnostics`` for that version is read: the
server's whole check (the buffer parsed into a model, lint-urdf's static rules with the workspace's
configuration, the findings turned into ranged diagnostics) plus the JSON-RPC both ways. The debounce
is excluded (``--debounce-ms 0``): with the default (150 ms) an editor sees the diagnostics 150 ms
plus this after the last keystroke of a burst. The server's CPU time per keystroke is read from
``/proc/PID/stat`` (Linux), since on a shared machine wall time includes waiting for a core.

A keystroke in a value is what the server checks fastest: it makes the new model from the one it has
and reuses the earlier check's work (``ar3cli/urdf/model_edit.py``, ``ar3cli/lint/reuse.py``). Two more
kinds are timed, each in a server process of its own (:data:`KINDS`): a line break typed after a
``</joint>`` or deleted (every element below moves: the buffer is parsed and its new lines copied into the
model), and a comment pasted or deleted (a node more or less, as an element added: a full load, every
rule). Last, an in-process breakdown of a
full check and of a keystroke in a value (load, rules, diagnostics).

Alternating with each keystroke, the same file is linted by a whole ``ar3cli lint-urdf --no-cache``
process (what a save hook or a terminal pays, interpreter start-up included), and the ratio is taken
round by round. Before the timed rounds: the first diagnostics after ``didOpen`` (cold: imports,
first model) and warm-up keystrokes. After them, the server's resident memory after the keystrokes
(``--memory-edits``, default 300), to show it does not grow with edits.

The generated robot (``--links``, default 300): a tree of revolute joints, six arms of 50 links off
a base, each link with an inertial, a cylinder visual and collision, origin, axis and limits:
no findings, so every rule runs to the end. ``--robot PATH`` times a real file instead (its
``<limit upper="...">`` values are the ones edited).

Usage (inside the project's venv)::

    python benchmarks/bench_server.py                 # 300 links, 20 rounds, ~1 minute on 2 cores
    python benchmarks/bench_server.py --runs 5 --links 1000
    python benchmarks/bench_server.py --robot path/to/robot.urdf
"""

from __future__ import annotations

import argparse
import json
import os
import queue
import re
import statistics
import subprocess
import sys
import threading
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import _timing  # noqa: E402 - after the sys.path line that finds it

ARM_LINKS = 50
"""Links per arm of the generated robot (the arms hang from the base)."""
TIMEOUT_S = 120


def robot(links: int) -> str:
    """A URDF of ``links`` links: a base and arms of :data:`ARM_LINKS` revolute links, no findings."""
    lines = ['<?xml version="1.0"?>', '<robot name="bench_server">', '  <link name="l0">',
             '    <inertial><mass value="5"/><inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial>',
             '    <visual><geometry><box size="0.3 0.3 0.1"/></geometry></visual>',
             '    <collision><geometry><box size="0.3 0.3 0.1"/></geometry></collision>', '  </link>']
    for index in range(1, links):
        parent = "l0" if index % ARM_LINKS == 1 or ARM_LINKS == 1 else f"l{index - 1}"
        lines += [f'  <link name="l{index}">',
                  '    <inertial><origin xyz="0 0 0.05"/><mass value="0.5"/>'
                  '<inertia ixx="0.0005" ixy="0" ixz="0" iyy="0.0005" iyz="0" izz="0.0002"/></inertial>',
                  '    <visual><origin xyz="0 0 0.05"/><geometry><cylinder radius="0.03" length="0.1"/></geometry></visual>',
                  '    <collision><origin xyz="0 0 0.05"/><geometry><cylinder radius="0.03" length="0.1"/></geometry>'
                  '</collision>', '  </link>',
                  f'  <joint name="j{index}" type="revolute">', f'    <parent link="{parent}"/>',
                  f'    <child link="l{index}"/>', f'    <origin xyz="{0.1 if parent == "l0" else 0} 0 0.1"/>',
                  '    <axis xyz="0 1 0"/>', '    <limit lower="-1.57" upper="1.57" effort="10" velocity="2"/>',
                  '  </joint>']
    lines.append("</robot>")
    return "\n".join(lines) + "\n"


class Client:
    """A minimal LSP client on a server process' pipes: requests, notifications, and a reader thread."""

    def __init__(self, command: list[str], cwd: Path) -> None:
        self.process = subprocess.Popen(command, stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                        stderr=subprocess.DEVNULL, cwd=cwd, env=_timing.BASE_ENV)
        self.messages: queue.Queue = queue.Queue()
        self.next_id = 0
        threading.Thread(target=self._read, daemon=True).start()

    def _read(self) -> None:
        stream = self.process.stdout
        while True:
            length = None
            while True:
                line = stream.readline()
                if not line:
                    self.messages.put(None)
                    return
                if not line.strip():
                    break
                name, _, value = line.decode("ascii").partition(":")
                if name.lower() == "content-length":
                    length = int(value)
            self.messages.put((time.perf_counter(), json.loads(stream.read(length))))

    def send(self, message: dict) -> float:
        """Write one message; the time it was written."""
        data = json.dumps({"jsonrpc": "2.0", **message}).encode("utf-8")
        self.process.stdin.write(b"Content-Length: %d\r\n\r\n%s" % (len(data), data))
        self.process.stdin.flush()
        return time.perf_counter()

    def wait(self, wanted) -> tuple[float, dict]:
        """The first message ``wanted(message)`` accepts, and when it was read (answering server requests)."""
        deadline = time.monotonic() + TIMEOUT_S
        while True:
            item = self.messages.get(timeout=max(0.01, deadline - time.monotonic()))
            if item is None:
                raise SystemExit("the server closed its output")
            when, message = item
            if "id" in message and "method" in message:
                self.send({"id": message["id"], "result": None})
            if wanted(message):
                return when, message

    def request(self, method: str, params) -> dict:
        self.next_id += 1
        number = self.next_id
        self.send({"id": number, "method": method, "params": params})
        return self.wait(lambda message: message.get("id") == number and "method" not in message)[1]

    def cpu_seconds(self) -> float:
        """The server's user + system CPU time so far (Linux ``/proc``; 0 elsewhere)."""
        try:
            fields = Path(f"/proc/{self.process.pid}/stat").read_text().rsplit(")", 1)[1].split()
        except OSError:
            return 0.0
        return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")

    def rss_mb(self) -> float:
        try:
            status = Path(f"/proc/{self.process.pid}/status").read_text()
        except OSError:
            return 0.0
        match = re.search(r"VmRSS:\s+(\d+) kB", status)
        return int(match.group(1)) / 1024 if match else 0.0

    def close(self) -> None:
        try:
            self.request("shutdown", None)
            self.send({"method": "exit", "params": None})
            self.process.wait(timeout=30)
        except (OSError, subprocess.TimeoutExpired, queue.Empty, SystemExit):
            self.process.kill()


class Keystrokes:
    """Keystrokes on the ``upper="..."`` values of the ``<limit>`` elements: the k-th deletes the last
    character of the k-th value (``1.57`` -> ``1.5``), and once every value had one, types them back,
    so no two keystrokes of a run (fewer than twice the joints) give the same text: a check answered
    from a cache of earlier texts could not pass for a check."""

    def __init__(self, text: str) -> None:
        self.places = []
        for match in re.finditer(r'<limit\b[^>]*\bupper="([^"]+)"', text):
            line = text.count("\n", 0, match.start(1))
            column = match.start(1) - (text.rfind("\n", 0, match.start(1)) + 1)
            self.places.append((line, column + len(match.group(1)) - 1, match.group(1)[-1]))
        if not self.places:
            raise SystemExit("the robot has no <limit upper=\"...\"> to edit")
        self.version = 1
        self.count = 0

    def next(self, uri: str) -> dict:
        """The next didChange: one character deleted, or typed back."""
        self.version += 1
        line, column, character = self.places[self.count % len(self.places)]
        typing_back = (self.count // len(self.places)) % 2 == 1
        self.count += 1
        start = {"line": line, "character": column}
        end = start if typing_back else {"line": line, "character": column + 1}
        return {"method": "textDocument/didChange", "params": {
            "textDocument": {"uri": uri, "version": self.version},
            "contentChanges": [{"range": {"start": start, "end": end}, "text": character if typing_back else ""}]}}


class Insertions:
    """Keystrokes that insert ``inserted`` at each ``</joint>`` (after it, or before it with ``before``), another
    joint each time and the insertions kept, then, once every joint has one, delete them again in the same
    order: no two texts are the same. A line break after ``</joint>`` moves every element below it (the server
    parses the buffer and copies the new lines into the model it has); a comment pasted before it adds a
    node, as a new element does (the server loads the buffer and runs every rule in full; a comment changes no
    finding, on any robot)."""

    def __init__(self, text: str, inserted: str, before: bool = False) -> None:
        self.text, self.inserted, self.before = text, inserted, before
        self.joints = len(re.findall(r"</joint>", text))
        if not self.joints:
            raise SystemExit("the robot has no </joint> to type at")
        self.version = 1
        self.count = 0

    def next(self, uri: str) -> dict:
        self.version += 1
        nth = self.count % self.joints
        adding = (self.count // self.joints) % 2 == 0
        self.count += 1
        where = [match.start() if self.before else match.end() for match in re.finditer(r"</joint>", self.text)][nth]
        at = where - len(self.inserted) if self.before and not adding else where
        start = self.position(at)
        if adding:
            self.text = self.text[:at] + self.inserted + self.text[at:]
            change = {"range": {"start": start, "end": start}, "text": self.inserted}
        else:
            change = {"range": {"start": start, "end": self.position(at + len(self.inserted))}, "text": ""}
            self.text = self.text[:at] + self.text[at + len(self.inserted):]
        return {"method": "textDocument/didChange", "params": {
            "textDocument": {"uri": uri, "version": self.version}, "contentChanges": [change]}}

    def position(self, offset: int) -> dict:
        """The LSP position of ``offset`` in the current text (ASCII: characters are UTF-16 units)."""
        return {"line": self.text.count("\n", 0, offset), "character": offset - (self.text.rfind("\n", 0, offset) + 1)}


KINDS = {"a line break after a `</joint>`, or that empty line deleted (every later element moves: the buffer is "
         "parsed, its new lines copied into the model the server has)": ("\n", False),
         "a comment `<!-- checked -->` pasted before a `</joint>`, or deleted (a node more or less, as an element "
         "added: a full load and every rule)": ("<!-- checked -->", True)}
"""The keystrokes timed besides those in a value: what they do, and (inserted text, before ``</joint>``)."""


def open_server(path: Path, text: str) -> tuple[Client, float, float, int]:
    """A server process with ``path`` open: (client, seconds to initialized, to the first diagnostics, their count)."""
    uri = path.as_uri()
    client = Client([*_timing.ar3cli_command(), "server", "--debounce-ms", "0"], path.parent)
    started = time.perf_counter()
    client.request("initialize", {"processId": os.getpid(), "rootUri": path.parent.as_uri(), "capabilities": {}})
    client.send({"method": "initialized", "params": {}})
    opened = client.send({"method": "textDocument/didOpen", "params": {"textDocument": {
        "uri": uri, "languageId": "xml", "version": 1, "text": text}}})
    first, published = client.wait(lambda m: m.get("method") == "textDocument/publishDiagnostics"
                                   and m["params"].get("version") == 1)
    return client, opened - started, first - opened, len(published["params"]["diagnostics"])


def keystroke(client: Client, keys: Keystrokes | Insertions, uri: str) -> tuple[float, float, int]:
    """One keystroke: (wall seconds to its diagnostics, server CPU seconds meanwhile, diagnostics count)."""
    cpu = client.cpu_seconds()
    message = keys.next(uri)
    version = message["params"]["textDocument"]["version"]
    sent = client.send(message)
    received, published = client.wait(lambda m: m.get("method") == "textDocument/publishDiagnostics"
                                       and m["params"].get("version") == version)
    return received - sent, client.cpu_seconds() - cpu, len(published["params"]["diagnostics"])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--links", type=int, default=300, help="links of the generated robot")
    parser.add_argument("--robot", type=Path, help="time this .urdf instead of a generated one")
    parser.add_argument("--runs", type=int, default=20, help="timed rounds (keystroke, then a lint-urdf process)")
    parser.add_argument("--warmup", type=int, default=5, help="keystrokes before the timed ones")
    parser.add_argument("--memory-edits", type=int, default=300, help="keystrokes before memory is read again")
    args = parser.parse_args()
    if args.runs < 5:
        raise SystemExit("--runs must be at least 5")
    if args.robot is not None:
        path = args.robot.resolve()
        text = path.read_text(encoding="utf-8")
    else:
        path = _timing.WORK / f"robot_{args.links}.urdf"
        text = robot(args.links)
        path.write_text(text)
    links = len(re.findall(r"<link\b", text))
    print(_timing.machine_header(f"bench_server.py: {path.name}, {links} links, {len(text) / 1024:.0f} KB"))
    uri = path.as_uri()
    client, to_initialized, to_first, findings = open_server(path, text)
    try:
        print(f"- server start to initialized: {to_initialized:.3f} s; didOpen to its first diagnostics "
              f"(cold: imports, first model): {to_first:.3f} s; {findings} diagnostics\n")
        keys = Keystrokes(text)
        for _ in range(args.warmup):
            keystroke(client, keys, uri)
        lint = _timing.Variant("ar3cli lint-urdf --no-cache (whole process)",
                               [*_timing.ar3cli_command(), "lint-urdf", "--no-cache", "--format", "json", str(path)],
                               ok_codes=(0, 1))
        lint.run()  # its warm-up
        walls, cpus, ratios = [], [], []
        for _ in range(args.runs):
            wall, cpu, count = keystroke(client, keys, uri)
            if count != findings:
                raise SystemExit(f"a keystroke gave {count} diagnostics, the file {findings}: not the same check")
            process = lint.run()
            lint.runs.append(process)
            walls.append(wall)
            cpus.append(cpu)
            ratios.append(process.wall / wall)
        memory_before = client.rss_mb()
        for _ in range(args.memory_edits):
            keystroke(client, keys, uri)
        memory_after = client.rss_mb()
    finally:
        client.close()
    others = {what: insertions(path, text, args.runs, args.warmup, findings, *how) for what, how in KINDS.items()}
    print(f"### keystroke to diagnostics, {links} links (debounce excluded: --debounce-ms 0)\n")
    print(f"{args.runs} rounds, each a keystroke then a lint-urdf process; medians; ratio = lint-urdf process / "
          "keystroke in the same round\n")
    print(timing_rows(walls, cpus))
    print(f"| `ar3cli lint-urdf --no-cache` process, wall | {1e3 * statistics.median(r.wall for r in lint.runs):.0f} ms "
          f"| {1e3 * min(r.wall for r in lint.runs):.0f} ms | | {1e3 * max(r.wall for r in lint.runs):.0f} ms |")
    print(f"\n- ratio lint-urdf process / keystroke: median {statistics.median(ratios):.1f}x "
          f"(rounds: {' '.join(f'{ratio:.1f}' for ratio in ratios)})")
    print(f"- server memory (VmRSS): {memory_before:.0f} MB after the timed rounds, {memory_after:.0f} MB after "
          f"{args.memory_edits} more keystrokes")
    for what, timed in others.items():
        print(f"\n### {what}\n\n{args.runs} rounds, another server process\n")
        print(timing_rows(*zip(*timed)))
    print(breakdown(path, text, args.runs))
    print(_timing.machine_footer())


def timing_rows(walls, cpus) -> str:
    """The table head and the wall and CPU rows (median, min, p90, max) of some keystrokes."""
    def p90(values) -> float:
        return statistics.quantiles(values, n=10, method="inclusive")[-1]

    return "\n".join([
        "| what | median | min | p90 | max |", "|---|---:|---:|---:|---:|",
        f"| keystroke -> publishDiagnostics, wall | {1e3 * statistics.median(walls):.1f} ms | {1e3 * min(walls):.1f} ms "
        f"| {1e3 * p90(walls):.1f} ms | {1e3 * max(walls):.1f} ms |",
        f"| server CPU per keystroke | {1e3 * statistics.median(cpus):.0f} ms | {1e3 * min(cpus):.0f} ms "
        f"| {1e3 * p90(cpus):.0f} ms | {1e3 * max(cpus):.0f} ms |"])


def insertions(path: Path, text: str, runs: int, warmup: int, findings: int, inserted: str,
               before: bool) -> list[tuple[float, float]]:
    """(wall, server CPU) of ``runs`` :class:`Insertions` keystrokes in a server of their own."""
    client, _initialized, _first, _count = open_server(path, text)
    try:
        keys = Insertions(text, inserted, before)
        for _ in range(warmup):
            keystroke(client, keys, path.as_uri())
        timed = []
        for _ in range(runs):
            wall, cpu, count = keystroke(client, keys, path.as_uri())
            if count != findings:
                raise SystemExit(f"a keystroke ({inserted!r}) gave {count} diagnostics, the file {findings}: "
                                 "not the same check")
            timed.append((wall, cpu))
        return timed
    finally:
        client.close()


def breakdown(path: Path, text: str, runs: int) -> str:
    """Where a check's CPU goes, measured in this process on the same robot (not a speed claim: the
    whole-process numbers above are): the buffer loaded into a model, lint-urdf's static rules on it, the
    findings turned into diagnostics; for a full check and for a keystroke in one value checked after it."""
    sys.path.insert(0, str(_timing.REPO))
    import gc

    from ar3cli.analysis.findings import static_findings
    from ar3cli.analysis.robot import RobotAnalysis
    from ar3cli.analysis.settings import AnalysisSettings
    from ar3cli.cli import GC_ALLOCATIONS
    from ar3cli.server.checks import Snapshot, diagnostics_by_file

    gc.set_threshold(GC_ALLOCATIONS, *gc.get_threshold()[1:])  # as the server process has it (ar3cli.cli.run)
    gc.collect()
    gc.freeze()  # as the server does once it has imported what a check needs (ar3cli.server.launch)
    settings = AnalysisSettings()
    names = ("load the buffer (parse, model)", "lint-urdf's static rules", "findings to diagnostics (ranges)")
    steps: dict[str, dict[str, list[float]]] = {"full": {name: [] for name in names},
                                                "edited": {name: [] for name in names}}
    keys = Keystrokes(text)
    earlier, current = None, text
    for index in range(runs + 2):
        for kind in ("full", "edited"):
            if kind == "full":
                changed = current + " " * (index + 1)  # a new buffer
            else:
                change = keys.next(path.as_uri())["params"]["contentChanges"][0]
                line, column = change["range"]["start"]["line"], change["range"]["start"]["character"]
                offset = sum(len(row) + 1 for row in current.split("\n")[:line]) + column
                removed = change["range"]["end"]["character"] - column
                current = current[:offset] + change["text"] + current[offset + removed:]
                changed = current + " " * (index + 1)  # the full check's buffer with the keystroke
            start = time.process_time()
            analysis = RobotAnalysis.load(path, settings, text=changed, earlier=earlier if kind == "edited" else None,
                                          editing=True)  # no earlier analysis: a full check
            loaded = time.process_time()
            found = static_findings(analysis).findings
            linted = time.process_time()
            diagnostics_by_file(found, analysis, Snapshot(path.as_uri(), path, index, changed), "utf-16")
            done = time.process_time()
            if kind == "edited" and analysis.edit is None:
                raise SystemExit("the breakdown's keystroke was not checked as an edit of the one before")
            earlier = analysis
            if index >= 2:  # the first two warm up imports and caches
                for name, seconds in zip(names, (loaded - start, linted - loaded, done - linted)):
                    steps[kind][name].append(seconds)
    lines = ["", f"in-process breakdown of one check (CPU time, median of {runs}; this process, same robot): a full "
             "check (a new buffer, loaded and linted in full) and a keystroke in one value checked after the one "
             "before, as the server does", "", "| step | full check, CPU ms | keystroke in a value, CPU ms |",
             "|---|---:|---:|"]
    lines += [f"| {name} | {1e3 * statistics.median(steps['full'][name]):.1f} "
              f"| {1e3 * statistics.median(steps['edited'][name]):.1f} |" for name in names]
    lines.append(f"| all | {1e3 * sum(statistics.median(v) for v in steps['full'].values()):.1f} "
                 f"| {1e3 * sum(statistics.median(v) for v in steps['edited'].values()):.1f} |")
    return "\n".join(lines) + "\n" + rule_costs(analysis, runs)


SHOWN_RULES = 10


def rule_costs(analysis, runs: int) -> str:
    """Each static rule's CPU time on the analysed model, one Context shared as the engine shares it
    (median of ``runs``): the rules worth making cheaper first."""
    from ar3cli.lint.context import Context

    rules = [rule for rule in analysis.settings.lint_options(False).rules() if rule.check is not None]
    spent: dict[str, list[float]] = {rule.code: [] for rule in rules}
    for _ in range(runs):
        context = Context(analysis.model)
        for rule in rules:
            start = time.process_time()
            for _hit in rule.check(context):
                pass
            spent[rule.code].append(time.process_time() - start)
        context.close()
    medians = sorted(((statistics.median(values), code) for code, values in spent.items()), reverse=True)
    total = sum(value for value, _ in medians)
    shown = ", ".join(f"{code} {1e3 * value:.1f}" for value, code in medians[:SHOWN_RULES])
    rest = sum(value for value, _ in medians[SHOWN_RULES:])
    return (f"\nthe {len(rules)} static rules, CPU ms each (median of {runs}, one shared Context): "
            f"{1e3 * total:.0f} in all; {shown}; the other {len(medians) - SHOWN_RULES} together {1e3 * rest:.1f}\n")


if __name__ == "__main__":
    main()
