"""The output boundary (issue 34): every command x every format, run on a robot whose file name and
link and joint names are hostile, forges no line, no workflow command, no image, link or tag.

The hostile parts: a newline followed by a workflow command (``::stop-commands::``, ``::error``), an
escape sequence, the C1 control CSI (0x9b), a bidi override (U+202E), a backtick, Markdown images
and links, an HTML ``<script>``, an ``@mention`` and a byte that is not UTF-8 (0xff). The commands
come from ``cli.COMMANDS`` and the formats from each command's ``--format`` choices (the format
registry), so a new command or format is walked too: :data:`ARGUMENTS` must say how to run every
command that reads a robot file, or the test fails.

Cost: one small robot; the commands run two at a time (each a fresh process, as a user runs them).
"""

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
import xml.etree.ElementTree as ET
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from html.parser import HTMLParser
from pathlib import Path

import pytest

from tests.conftest import REPO

MARKERS = ("::stop-commands::", "::error file=x::")
"""What a forged line would start with (after the newline in a name)."""
RAW = ("\x1b", "\x9b", "\u202e", "\r")
"""Characters no output may carry raw (JSON writes them as ``\\u`` escapes)."""

FILE_PART = "r\n::stop-commands::pwned\x1b[2J\u202e\x9b`![f](f.png)<script>@octocat\udcff"
"""The hostile part of the robot's file name (``\\udcff``: the byte 0xff, as Python names it)."""
NAME = ("L&#10;::error file=x::forged &#x9b;&#x202e; `tick` ![pwn](https://evil.example/x.png) "
        "[Approve](https://evil.example/ok) &lt;script&gt;alert(1)&lt;/script&gt; @octocat www.evil.example")
"""The hostile part of every link and joint name, as the XML writes it."""
MESH = "m&#10;::error file=x::forged &#x9b;&#x202e; `tick` ![pwn](x.png) &lt;script&gt;"
"""The hostile part of a mesh file name (no ``//``); the mesh exists, so the robot loads in pybullet."""
MESH_FILE = "m\n::error file=x::forged \x9b\u202e `tick` ![pwn](x.png) <script>.stl"
SHOWN = ("![pwn](https://evil.example/x.png)", "[Approve](https://evil.example/ok)", "`tick`", "<script>alert(1)")
"""Parts of :data:`NAME` a rendered Markdown or HTML page must show as text (an image, a link, a
code span or a tag would swallow them)."""

INERTIAL = '<inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>'
BOX = '<geometry><box size="0.1 0.1 0.1"/></geometry>'
XACRO = f"""<robot name="x" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:include filename="none{MESH}*.xacro"/>
  <link name="{NAME}">{INERTIAL}</link>
</robot>
"""
"""A xacro file whose include matches nothing: xacro's warning quotes the pattern, and ar3cli's note
the file name."""


def robot(suffix: str = "", orphan: bool = False) -> str:
    """A base and a moving link whose joint has effort 0 (J008 names the joint) and whose mesh is
    named as hostile: findings that quote the names, and a robot that loads in pybullet and MuJoCo.
    ``orphan``: an unconnected link too (S005 names the links; pybullet would crash on it)."""
    link = f"{NAME} link{suffix}"
    second = f'<link name="{NAME} orphan"/>' if orphan else ""
    return f"""<?xml version="1.0"?>
<robot name="{NAME}">
  <link name="base">{INERTIAL}<collision>{BOX}</collision></link>
  <link name="{link}">{INERTIAL}<visual><geometry><mesh filename="meshes/{MESH}.stl"/></geometry></visual>
    <collision><origin xyz="0 0 0.5"/>{BOX}</collision></link>
  {second}
  <joint name="{NAME} joint" type="revolute"><parent link="base"/><child link="{link}"/><axis xyz="0 0 1"/>
    <origin xyz="0 0 0.1"/><limit lower="-1" upper="1" effort="0" velocity="1"/></joint>
</robot>
"""


def tetrahedron() -> bytes:
    """A binary STL of four triangles, 5 cm across."""
    import struct

    corners = [(0, 0, 0), (0.05, 0, 0), (0, 0.05, 0), (0, 0, 0.05)]
    faces = [(0, 2, 1), (0, 1, 3), (0, 3, 2), (1, 2, 3)]
    triangles = b"".join(struct.pack("<12fH", 0, 0, 0, *corners[a], *corners[b], *corners[c], 0) for a, b, c in faces)
    return b"\0" * 80 + struct.pack("<I", len(faces)) + triangles


def hostile_name(folder: Path, stem: str) -> Path:
    """``folder/stem + FILE_PART + .urdf``, the name as bytes (0xff included)."""
    return folder / os.fsdecode(os.fsencode(stem + FILE_PART + ".urdf"))


@dataclass
class Run:
    command: str
    fmt: str
    args: list[str]
    env: dict[str, str] = field(default_factory=dict)
    code: int = 0
    stdout: bytes = b""
    stderr: bytes = b""
    files: dict[str, bytes] = field(default_factory=dict)
    """Files the run wrote that people or CI read (the step summary, an HTML page)."""


@pytest.fixture(scope="module")
def workspace(tmp_path_factory) -> Path:
    """robots/: the hostile robot and one with an orphan link; a second hostile robot for diff; a git repository
    (for ``--changed-since``); a scan store made once for scan-report."""
    root = tmp_path_factory.mktemp("hostile")
    robots = root / "robots"
    robots.mkdir()
    for folder in (robots, root):
        (folder / "meshes").mkdir()
        (folder / "meshes" / MESH_FILE).write_bytes(tetrahedron())
    hostile_name(robots, "a").write_text(robot(), encoding="utf-8")
    (robots / "other.urdf").write_text(robot(orphan=True), encoding="utf-8")
    (robots / os.fsdecode(os.fsencode("x" + FILE_PART + ".xacro"))).write_text(XACRO, encoding="utf-8")
    hostile_name(root, "new").write_text(robot(" moved").replace('xyz="0 0 0.1"', 'xyz="0 0 0.2"'), encoding="utf-8")
    git = ["git", "-c", "user.name=t", "-c", "user.email=t@example.com", "-c", "commit.gpgsign=false", "-C", str(root)]
    for args in (["init", "-q"], ["add", "robots/other.urdf"], ["commit", "-qm", "good"]):
        subprocess.run([*git, *args], check=True, capture_output=True)
    done = _cli(["scan", "robots", "--store", "store.sqlite"], root)
    assert done.returncode in (0, 1), done.stderr
    return root


def _cli(args: list[str], cwd: Path, env: dict[str, str] | None = None) -> subprocess.CompletedProcess:
    environment = {**os.environ, "PYTHONPATH": str(REPO), "NO_COLOR": "1", "AR3CLI_NO_CACHE": "1", **(env or {})}
    environment.pop("GITHUB_ACTIONS", None)
    environment.pop("GITHUB_STEP_SUMMARY", None)
    environment.update(env or {})
    return subprocess.run([sys.executable, "-m", "ar3cli", *args], cwd=cwd, env=environment, capture_output=True,
                          timeout=300, stdin=subprocess.DEVNULL)


def arguments(root: Path) -> dict[str, list[list[str]]]:
    """How to run each command on the hostile robot (a list of argument lists: several runs)."""
    robots = root / "robots"
    (hostile,) = [path for path in robots.iterdir() if path.name.startswith("a")]
    (moved,) = [path for path in root.iterdir() if path.name.startswith("new")]
    one, folder = os.fsdecode(hostile.relative_to(root)), "robots"
    runs = {
        "info": [[one]],
        "render": [[one, "-o", "picture.png", "--width", "64", "--height", "48"]],
        "fk-verify": [[one, "-n", "2"]],
        "lint-urdf": [[folder], ["--changed-since", "HEAD", folder]],
        "sample-collisions": [[one, "-n", "4"]],
        "cross-check": [[one, "-n", "1"]],
        "diff": [[one, os.fsdecode(moved.relative_to(root)), "-n", "2"]],
        "scan": [[folder, "--store", "scanned.sqlite"]],
        "scan-report": [["store.sqlite", "--keep", "loads", "--keep-list", "keep.txt"]],
        "report": [[one, "-o", "page.html", "-n", "2"]],
        # expand's stdout without -o is the URDF itself (data, as xacro prints it; XML escapes what XML
        # must): what is checked here is what it says about the run
        "expand": [[one, "-o", "expanded.urdf"]],
    }
    for command in COMMANDS:
        if command.startswith("fix-"):
            runs[command] = [[one, "--diff", *FIXER_OPTIONS.get(command, [])]]
    return runs


FIXER_OPTIONS = {"fix-mesh-paths": ["--package", "pkg=."]}
"""Options a fixer cannot run without."""
NO_ROBOT_INPUT = {
    "install-check": "checks the installation: reads no robot file",
    "grasp-demo": "runs the bundled AR3 and a cube: reads no robot file",
}
"""Commands that read no robot file (no argument): nothing of an attacker's reaches their output."""
FRONT_ENDS = {
    "server": ("tests/test_server.py", "test_hostile_names_reach_the_editor_as_plain_text"),
    "view": ("tests/test_view.py", "test_the_panel_shows_a_hostile_robot_s_names_as_text"),
}
"""Commands without ``--format`` that read robot files another way (an editor's buffers over LSP, a
browser): the test named here walks their output with the same hostile names."""


def _commands() -> dict[str, object]:
    import typer

    from ar3cli.cli import application

    return typer.main.get_command(application([])).commands


COMMANDS = _commands()


def _formats(command) -> list[str]:
    (option,) = [param for param in command.params if "--format" in param.opts]
    return list(option.type.choices)


def test_every_command_is_walked_or_reads_no_robot_file(workspace):
    from ar3cli.cli import COMMANDS as NAMES

    walked = set(arguments(workspace))
    assert walked | set(NO_ROBOT_INPUT) | set(FRONT_ENDS) == set(NAMES), "say how to run a new command in arguments()"
    for module, test in FRONT_ENDS.values():
        assert f"def {test}(" in (REPO / module).read_text(), (module, test)
    for name in NO_ROBOT_INPUT:
        assert not [param for param in COMMANDS[name].params if param.param_type_name == "argument"], name


def _runs(root: Path) -> list[Run]:
    runs = []
    for command, argument_lists in arguments(root).items():
        for fmt in _formats(COMMANDS[command]):
            for args in argument_lists:
                env = {"GITHUB_STEP_SUMMARY": str(root / f"summary-{command}-{len(runs)}.md")} if fmt == "github" else {}
                runs.append(Run(command, fmt, [command, *args, "--format", fmt], env))
    return runs


@pytest.fixture(scope="module")
def finished(workspace) -> list[Run]:
    """Every run, two at a time; each keeps what it wrote to stdout, stderr and the files people read."""
    runs = _runs(workspace)

    def one(run: Run) -> Run:
        folder = workspace / f"run-{runs.index(run)}"
        shutil.copytree(workspace, folder, ignore=shutil.ignore_patterns("run-*"), symlinks=True)
        done = _cli(run.args, folder, run.env)
        run.code, run.stdout, run.stderr = done.returncode, done.stdout, done.stderr
        for name in ("page.html", "keep.txt"):
            if (folder / name).exists():
                run.files[name] = (folder / name).read_bytes()
        if "GITHUB_STEP_SUMMARY" in run.env and Path(run.env["GITHUB_STEP_SUMMARY"]).exists():
            run.files["step summary"] = Path(run.env["GITHUB_STEP_SUMMARY"]).read_bytes()
        return run

    with ThreadPoolExecutor(max_workers=2) as pool:
        return list(pool.map(one, runs))


def _text(data: bytes) -> str:
    return data.decode("utf-8")  # strict: a byte that is not UTF-8 must have been escaped


def test_no_run_crashes_and_every_format_was_run(finished):
    assert {(run.command, run.fmt) for run in finished} >= {("lint-urdf", "github"), ("diff", "markdown"),
                                                            ("scan-report", "markdown"), ("lint-urdf", "html")}
    for run in finished:
        stderr = _text(run.stderr)
        assert run.code in (0, 1, 2) and "Traceback" not in stderr and "internal error" not in stderr, (run.args, stderr)


def test_no_output_carries_a_raw_control_character_or_forges_a_line(finished):
    for run in finished:
        outputs = {"stdout": run.stdout, "stderr": run.stderr, **run.files}
        for where, data in outputs.items():
            text = _text(data)
            assert not [char for char in RAW if char in text], (run.args, where)
            for line in text.splitlines():
                start = line.lstrip()
                assert not start.startswith(MARKERS) and not start.startswith("pwned"), (run.args, where, line)
                if start.startswith("::"):  # only the github format's own annotations
                    assert run.fmt == "github" and where == "stdout", (run.args, line)
                    assert re.match(r"::(error|warning|notice)( [^:]*)?::", start), (run.args, line)


def test_the_names_are_shown_escaped_in_text_and_exact_in_json(finished):
    text = next(run for run in finished if run.args[:2] == ["lint-urdf", "robots"] and run.fmt == "text")
    shown = _text(text.stdout)
    assert "\\x0a::stop-commands::pwned\\x1b[2J\\u202e\\x9b`" in shown and "\\xff.urdf" in shown
    assert "robots/other.urdf:" in shown and "3 files checked" in shown  # the batch went on past the 0xff name
    notes = _text(text.stderr)
    assert "ar3cli: note: robots/xr\\x0a::stop-commands::pwned" in notes and "xacro says" in notes
    data = json.loads(next(run for run in finished if run.args[:2] == ["lint-urdf", "robots"]
                           and run.fmt == "json").stdout)
    paths = {finding["path"] for finding in data["findings"]}
    assert "robots/a" + FILE_PART + ".urdf" in paths  # JSON keeps the exact name (\udcff: the byte 0xff)
    assert not [f for f in data["findings"] if f["rule"] == "F002"]  # xacro's banner naming the file stays XML


class _Tags(HTMLParser):
    def __init__(self) -> None:
        super().__init__()
        self.tags: list[tuple[str, dict]] = []
        self.text: list[str] = []

    def handle_starttag(self, tag, attrs):
        self.tags.append((tag, dict(attrs)))

    def handle_data(self, data):
        self.text.append(data)


CODE_SPAN = re.compile(r"(?<!`)(`+)(?!`).*?(?<!`)\1(?!`)")
"""A Markdown code span: inside one, GitHub makes no autolink and no mention."""


def _rendered(markdown: str) -> _Tags:
    """``markdown`` rendered as CommonMark with GitHub's tables and strikethrough, raw HTML allowed
    (GitHub keeps <details>; a forged <script> would show here as a tag)."""
    from markdown_it import MarkdownIt

    parsed = _Tags()
    parsed.feed(MarkdownIt("commonmark", {"html": True}).enable(["table", "strikethrough"]).render(markdown))
    return parsed


def test_markdown_shows_names_as_text_never_as_image_link_tag_or_code(finished):
    pages = [(run, _text(run.stdout if run.fmt == "markdown" else run.files["step summary"]))
             for run in finished if run.fmt == "markdown" or "step summary" in run.files]
    assert {run.command for run, _ in pages} >= {"lint-urdf", "diff", "scan-report"}
    for run, page in pages:
        parsed = _rendered(page)
        assert {tag for tag, _ in parsed.tags} <= {"h2", "h3", "p", "table", "thead", "tbody", "tr", "th", "td", "code",
                                                  "em", "details", "summary", "br"}, run.args
        text = "".join(parsed.text)
        if run.command != "scan-report":  # scan-report lists paths and rules, not messages
            assert all(part in text for part in SHOWN), (run.args, text)
        assert "`![f](f.png)<script>" in text, run.args  # the file name's code span held
        # GitHub's autolinks and mentions, which CommonMark alone does not make (none in a code span):
        prose = CODE_SPAN.sub("", page)
        assert not re.search(r"(?<!\\)(https?:(?=//)|www\.)", prose) and not re.search(r"@\w", prose), run.args


def test_html_pages_escape_every_name(finished):
    pages = [(run, _text(data)) for run in finished for name, data in run.files.items() if name == "page.html"]
    pages += [(run, _text(run.stdout)) for run in finished if run.fmt == "html"]
    assert pages
    for run, page in pages:
        parsed = _Tags()
        parsed.feed(page)
        scripts = [attrs for tag, attrs in parsed.tags if tag == "script"]
        assert len(scripts) <= 2 and not [attrs for tag, attrs in parsed.tags if tag in ("img", "a")
                                          and "evil" in " ".join(str(v) for v in attrs.values())], run.args
        assert "<script>alert(1)" in "".join(parsed.text), run.args


def test_a_keep_list_holds_one_real_path_a_line(finished):
    """A file name with a newline would write a second, forged path into scan-report's keep-list."""
    for run in finished:
        if "keep.txt" in run.files:
            paths = run.files["keep.txt"].decode("utf-8", "surrogateescape").splitlines()
            assert [Path(path).name for path in paths] == ["other.urdf"]
            if run.fmt != "json":
                assert "left out 2 whose name holds a line break" in _text(run.stdout + run.stderr), run.args


def test_junit_sarif_and_json_are_well_formed(finished):
    for run in finished:
        if run.fmt == "junit":
            ET.fromstring(run.stdout)
        elif run.fmt in ("json", "sarif"):
            json.loads(run.stdout)


# ---- the escaping functions, one per kind of output --------------------------------------------------


def test_terminal_shows_every_control_and_keeps_tab_and_unicode():
    from ar3cli.output.escape import terminal

    assert terminal("plain ümlaut 日本\tx") == "plain ümlaut 日本\tx"
    assert terminal("a\nb\rc\x1b[2J\x9b\u202e\u2028\udcff") == "a\\x0ab\\x0dc\\x1b[2J\\x9b\\u202e\\u2028\\xff"


def test_markdown_code_span_survives_backticks_and_pipes():
    from ar3cli.output.escape import markdown_code

    assert markdown_code("a.urdf:3:1") == "`a.urdf:3:1`"
    assert markdown_code("a`b") == "``a`b``"
    assert markdown_code("`x``") == "``` `x`` ```"
    assert markdown_code("a|b") == "`a\\|b`"


def test_markdown_text_escapes_what_would_render():
    from ar3cli.output.escape import markdown_text

    text = markdown_text("![x](https://e.x/i.png) [ok](u) `c` *b* <i> a|b $m$ ~s~ www.e.x @team")
    assert text == ("\\!\\[x\\](https\\://e.x/i.png) \\[ok\\](u) \\`c\\` \\*b\\* &lt;i&gt; a\\|b \\$m\\$ \\~s\\~ "
                    "www\\.e.x @\u2060team")


def test_a_fixers_diff_quotes_file_lines_inertly(monkeypatch):
    from ar3cli.output.report import quoted

    patch = "--- a/r.urdf\n+++ b/r.urdf\n@@ -1 +1 @@\n- <a/>\x1b[2J\r\n+ ::error::forged\r\n"
    assert quoted(patch) == "--- a/r.urdf\n+++ b/r.urdf\n@@ -1 +1 @@\n- <a/>\\x1b[2J\r\n+ ::error::forged\r\n"
    inert = quoted(patch)
    monkeypatch.setenv("GITHUB_ACTIONS", "true")  # the runner reads " ::error::x" as a command: stop them
    wrapped = quoted(patch)
    token = wrapped.split("\n", 1)[0].removeprefix("::stop-commands::")
    assert len(token) == 32 and wrapped == f"::stop-commands::{token}\n{inert}::{token}::\n"


# ---- bounded output (issue 34, item 2) -------------------------------------------------------------------


def test_listed_names_ten_and_counts_the_rest():
    from ar3cli.findings import listed

    assert listed(["a", "b"]) == "a, b"
    assert listed(map(str, range(5000))) == "0, 1, 2, 3, 4, 5, 6, 7, 8, 9 and 4,990 more"
    assert listed("abcd", 2, separator=" -> ") == "a -> b and 2 more"


def test_thousands_of_orphan_links_make_linear_output(cli, tmp_path):
    """5,000 orphans once printed 170 MB of annotations: each S005 message listed every root."""
    links = 2000
    body = "".join(f'<link name="orphan_{index}"/>' for index in range(1, links))
    (tmp_path / "orphans.urdf").write_text(f'<robot name="o"><link name="base"/>{body}</robot>')
    document = json.loads(cli("lint-urdf", "orphans.urdf", "--format", "json", cwd=tmp_path).stdout)
    messages = [finding["message"] for finding in document["findings"] if finding["rule"] == "S005"]
    assert len(messages) == links - 1 and max(map(len, messages)) < 200
    assert messages[0].endswith("(2000 roots: base, orphan_1, orphan_2, orphan_3, orphan_4, orphan_5, orphan_6, "
                                "orphan_7, orphan_8, orphan_9 and 1,990 more)")
    summary = tmp_path / "summary.md"
    github = cli("lint-urdf", "orphans.urdf", "--format", "github", cwd=tmp_path, env={"GITHUB_STEP_SUMMARY": str(summary)})
    (annotation, verdict) = github.stdout.splitlines()
    assert annotation.startswith("::error file=orphans.urdf,line=") and "title=S005 (1%2C999 in this file)::1999x: " in annotation
    assert verdict.startswith("FAILED: 1 file checked, 1999 errors") and len(github.stdout) < 1000
    assert summary.stat().st_size < 10_000 and "and 1,979 more" in summary.read_text()  # 20 in the details
    text = cli("lint-urdf", "orphans.urdf", cwd=tmp_path).stdout  # piped: one line for the alike findings
    assert len(text.splitlines()) == 2 and "1999x: link 'orphan_1' is not connected" in text
    every = cli("lint-urdf", "orphans.urdf", "--no-group", cwd=tmp_path).stdout.splitlines()
    assert len(every) == 1002 and every[-2] == "orphans.urdf: (and 999 more rows: --format json lists them all)"


def test_tables_and_trees_show_at_most_a_thousand_rows():
    from ar3cli.output.report import Table, Tree, bounded, plain_table, plain_tree

    text = plain_table(bounded(Table("t", ["n"], [[n] for n in range(2500)])))
    assert text.count("\n| ") == 1001 and "(and 1,500 more rows: --format json lists them all)" in text
    chain = root = Tree("root")
    for index in range(3000):  # a chain: deep, and long
        chain.children.append(Tree(f"l{index}"))
        chain = chain.children[0]
    lines = plain_tree(root).splitlines()
    assert len(lines) == 1001 and lines[-1].strip() == "- (and 2,001 more nodes: --format json lists them all)"
    assert max(map(len, lines)) < 100 and lines[40].lstrip().startswith("- [depth 40] l39")
