"""``ar3cli report`` and ``lint-urdf --format html``: self-contained pages whose numbers are the JSON
outputs of the same run, with every robot-file string escaped, checked in headless Chromium (no
console message, no network request, a picture that is not blank). The browser tests are skipped
when Debian's ``chromium`` is not installed (.ci/run installs it).

Set ``AR3CLI_REPORT_SCREENSHOT=docs/images/report.png`` to save the AR3 page's screenshot (README).
"""

from __future__ import annotations

import html.parser
import importlib.util
import json
import os
import re
import shutil
import subprocess
from pathlib import Path

import pytest

from tests.conftest import ASSETS, REPO, run_cli

AR3 = ASSETS / "ar3" / "ar3.urdf"
SAMPLES = "12"
SEED = "3"
EVIL = "<script>alert(1)</script>"
CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
needs_chromium = pytest.mark.skipif(CHROMIUM is None, reason="headless Chromium is not installed "
                                                             "(apt-get install chromium; .ci/run does)")

EVIL_URDF = """<?xml version="1.0"?>
<robot name="&lt;img src=x onerror=alert(2)&gt;">
  <link name="base"><inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/>
    </inertial><collision><geometry><box size="0.2 0.2 0.1"/></geometry></collision>
    <visual><geometry><box size="0.2 0.2 0.1"/></geometry></visual></link>
  <link name="&lt;script&gt;alert(1)&lt;/script&gt;">
    <collision><origin xyz="0 0 0.3"/><geometry><cylinder radius="0.04" length="0.5"/></geometry></collision>
    <visual><origin xyz="0 0 0.3"/><geometry><cylinder radius="0.04" length="0.5"/></geometry></visual></link>
  <link name="tip&quot;'&amp;"><inertial><origin xyz="0 0 0.1"/><mass value="0.2"/>
    <inertia ixx="0.001" iyy="0.001" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><origin xyz="0 0 0.1"/><geometry><box size="0.05 0.05 0.2"/></geometry></collision>
    <visual><origin xyz="0 0 0.1"/><geometry><box size="0.05 0.05 0.2"/></geometry></visual></link>
  <joint name="j1" type="revolute"><parent link="base"/><child link="&lt;script&gt;alert(1)&lt;/script&gt;"/>
    <origin xyz="0 0 0.05"/><axis xyz="0 1 0"/><limit lower="-1" upper="1" effort="5" velocity="1"/></joint>
  <joint name="j2" type="revolute"><parent link="&lt;script&gt;alert(1)&lt;/script&gt;"/><child link="tip&quot;'&amp;"/>
    <origin xyz="0 0 0.6"/><axis xyz="0 1 0"/><limit lower="-2" upper="2" effort="0.1" velocity="1"/></joint>
</robot>
"""


def _island(page: str) -> dict:
    found = re.search(r'<script type="application/json" id="data">(.*?)</script>', page, re.S)
    assert found, "the page has no data island"
    return json.loads(found.group(1))


def _json(*args: str) -> dict:
    done = run_cli(*args, "--format", "json")
    assert done.code in (0, 1), done.stderr
    return json.loads(done.stdout)


@pytest.fixture(scope="module")
def pages(tmp_path_factory) -> dict[str, Path]:
    """The AR3's report, the hostile robot's report and a lint-urdf batch page, made once."""
    folder = tmp_path_factory.mktemp("report")
    evil = folder / "evil.urdf"
    evil.write_text(EVIL_URDF, encoding="utf-8")
    made = {"ar3": AR3, "evil": evil}
    out = {}
    for name, robot in made.items():
        done = run_cli("report", str(robot), "-o", str(folder / f"{name}.html"), "--samples", SAMPLES, "--seed", SEED)
        assert done.code == 0, done.stderr
        out[name] = folder / f"{name}.html"
    batch = run_cli("lint-urdf", "--format", "html", str(evil), "tests/data/xacro/arm.urdf.xacro")
    assert batch.code == 1, batch.stderr
    (folder / "lint.html").write_text(batch.stdout, encoding="utf-8")
    out["lint"] = folder / "lint.html"
    out["evil_urdf"] = evil
    return out


@pytest.mark.parametrize("name", ["ar3", "evil", "lint"])
def test_page_is_self_contained(pages, name):
    page = pages[name].read_text(encoding="utf-8")
    assert page.startswith("<!DOCTYPE html>")
    assert "default-src 'none'; img-src data:; style-src 'unsafe-inline'; script-src 'unsafe-inline'" in page
    references = _Tags.of(page).references
    assert all(value.startswith(("data:", "#")) for value in references), references
    assert not re.search(r"https?://", page.split('id="data">')[0]), "a URL outside the data island"
    assert not re.search(r"<link\b|@import|url\(", page)


def test_robot_strings_are_escaped(pages):
    """A link named <script>alert(1)</script> is text on the page, never markup (nor in the JSON island)."""
    for name in ("evil", "lint"):
        page = pages[name].read_text(encoding="utf-8")
        assert EVIL not in page and "<img src=x" not in page and "<script>alert" not in page
        assert _Tags.of(page).tags.count("script") == 2  # the data island and the page's own script
        assert "&lt;script&gt;alert(1)&lt;/script&gt;" in page
    island = _island(pages["evil"].read_text(encoding="utf-8"))
    assert EVIL in [link["name"] for link in island["info"]["links"]]
    assert EVIL in island["collisions"]["links"]


def test_numbers_equal_the_json_outputs(pages):
    """The island holds what info, lint-urdf, sample-collisions, fk-verify and (MuJoCo installed) cross-check
    print with --format json."""
    island = _island(pages["ar3"].read_text(encoding="utf-8"))
    common = ("--samples", SAMPLES, "--seed", SEED)
    assert island["info"] == _json("info", str(AR3), "--torques", *common)
    lint = _json("lint-urdf", str(AR3))
    assert island["lint"]["summary"] == lint["summary"] and island["lint"]["findings"] == lint["findings"]
    collisions = _json("sample-collisions", str(AR3), *common)
    timing = ("elapsed_s", "configs_per_second", "jobs")
    assert {k: v for k, v in island["collisions"].items() if k not in timing} == \
        {k: v for k, v in collisions.items() if k not in timing}
    assert island["fk"] == _json("fk-verify", str(AR3), *common)
    if importlib.util.find_spec("mujoco") is None:
        assert island["cross_check"] is None
    else:
        cross = _json("cross-check", str(AR3), *common)
        assert {k: v for k, v in island["cross_check"].items() if k not in ("passed", "lines")} == cross
        assert island["cross_check"]["passed"] is cross["agree"]


def test_findings_carry_source_lines_and_fixes(pages):
    """The hostile robot has findings (a link without inertial, a weak joint): each cites its line."""
    page = pages["evil"].read_text(encoding="utf-8")
    island = _island(page)
    assert island["lint"]["summary"]["findings"] > 0
    assert "<mark>" in page and "fix: <code>ar3cli fix-inertia" in page
    assert island["info"]["torques"]["too_weak"] == ["j2"]


def test_xacro_findings_cite_the_xacro_source(pages):
    page = pages["lint"].read_text(encoding="utf-8")
    assert "tests/data/xacro/macros/arm_segment.xacro:" in page
    assert page.count("<section") == 2


def test_report_needs_an_output(tmp_path):
    done = run_cli("report", str(AR3))
    assert done.code == 2 and "--output" in done.stderr and "Traceback" not in done.stderr


class _Tags(html.parser.HTMLParser):
    """Every tag name and every src/href/action/srcset value of a page, as the browser parses it."""

    def __init__(self) -> None:
        super().__init__()
        self.tags: list[str] = []
        self.references: list[str] = []

    @classmethod
    def of(cls, page: str) -> _Tags:
        parser = cls()
        parser.feed(page)
        return parser

    def handle_starttag(self, tag, attrs):
        self.tags.append(tag)
        self.references += [value or "" for key, value in attrs if key in ("src", "href", "action", "srcset",
                                                                          "xlink:href", "poster", "data")]


class _Counts(html.parser.HTMLParser):
    """The ``data-count`` numbers and the root's ``data-loaded`` of a dumped DOM."""

    def __init__(self) -> None:
        super().__init__()
        self.counts: dict[str, int] = {}
        self.loaded: str | None = None
        self._key: str | None = None

    def handle_starttag(self, tag, attrs):
        attributes = dict(attrs)
        if tag == "html":
            self.loaded = attributes.get("data-loaded")
        self._key = attributes.get("data-count")

    def handle_data(self, data):
        if self._key and data.strip():
            self.counts.setdefault(self._key, int(data))
            self._key = None


def _chromium(page: Path, *args: str, profile: Path) -> subprocess.CompletedProcess:
    return subprocess.run([CHROMIUM, "--headless", "--disable-gpu", "--no-sandbox", "--no-first-run",
                           "--enable-logging=stderr", "--v=0", f"--user-data-dir={profile}", *args, page.as_uri()],
                          capture_output=True, text=True, timeout=120, stdin=subprocess.DEVNULL)


@needs_chromium
@pytest.mark.parametrize("name", ["ar3", "evil", "lint"])
def test_chromium_renders_the_page(pages, name, tmp_path):
    """No console message at all (a script error, or a blocked request: the CSP reports every one), a
    screenshot that is not one colour, and the counts the browser shows equal the JSON's."""
    from PIL import Image

    shot = tmp_path / "page.png"
    done = _chromium(pages[name], f"--screenshot={shot}", "--window-size=1200,1800", profile=tmp_path / "profile")
    console = [line for line in done.stderr.splitlines() if ":CONSOLE" in line]
    assert not console, console
    with Image.open(shot) as image:
        colours = image.convert("RGB").getcolors(maxcolors=1 << 16)
        assert colours is None or len(colours) > 50, "the screenshot is blank"
        if name == "ar3" and os.environ.get("AR3CLI_REPORT_SCREENSHOT"):
            image.crop((0, 0, 1200, 1400)).save(REPO / os.environ["AR3CLI_REPORT_SCREENSHOT"], optimize=True)
    dom = _chromium(pages[name], "--dump-dom", profile=tmp_path / "profile")
    parser = _Counts()
    parser.feed(dom.stdout)
    island = _island(pages[name].read_text(encoding="utf-8"))
    summary = island["summary"] if name == "lint" else island["lint"]["summary"]
    assert parser.loaded is not None, "the page's script did not run"
    assert parser.counts == {key: summary[key] for key in ("error", "warning", "info", "findings")}
