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

AR3 = (ASSETS / "ar3" / "ar3.urdf").relative_to(REPO)
"""Relative to the repository (run_cli's folder): the page's header names no machine path (README's picture)."""
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
    <origin xyz="0 0 0.05"/><axis xyz="0 1 0"/><limit lower="0.2" upper="1" effort="5" velocity="1"/></joint>
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
    """The island holds what info, lint-urdf --sim, sample-collisions, fk-verify and (MuJoCo installed)
    cross-check print with --format json."""
    island = _island(pages["ar3"].read_text(encoding="utf-8"))
    common = ("--samples", SAMPLES, "--seed", SEED)
    assert island["info"] == _json("info", str(AR3), "--torques", *common)
    lint = _json("lint-urdf", "--sim", str(AR3))
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


def test_one_verdict_at_the_top_built_from_every_section(pages):
    """The verdict comes first and is the worst status of the sections' checks; each section is
    collapsed to its own status, which is its check's; the findings include the PyBullet rules; no
    card says "lint passed" while a section warns."""
    page = pages["evil"].read_text(encoding="utf-8")
    island = _island(page)
    verdict = island["verdict"]
    statuses = {check["key"]: check["status"] for check in verdict["checks"]}
    assert set(statuses) == {"findings", "renders", "collisions", "torques", "fk", "cross-check"}
    assert statuses["torques"] == "warning"  # j2 cannot hold the tip up
    rank = {"fail": 2, "warning": 1}
    worst = max(rank.get(status, 0) for status in statuses.values())
    assert verdict["status"] == {2: "fail", 1: "warning", 0: "pass"}[worst]
    assert verdict["headline"].startswith(verdict["status"].upper() + ": ")
    assert page.index('id="verdict"') < page.index("<nav>") < page.index('id="summary"')
    assert f'data-verdict="{verdict["status"]}"' in page
    for key, status in statuses.items():
        assert re.search(rf'<details class="section" id="{re.escape(key)}" data-status="{status}">', page), key
    assert island["lint"]["summary"]["info"] + island["lint"]["summary"]["warning"] > 0
    assert {f["rule"][0] for f in island["lint"]["findings"]} >= {"P"}, "the PyBullet rules ran"
    assert "lint</b>" not in page and ">passed<" not in page


def test_the_page_says_the_home_pose_is_not_all_zeros(pages):
    """j1's range is [0.2, 1]: the pictures show it at 0.6, and the page says so at the top and above them."""
    page = pages["evil"].read_text(encoding="utf-8")
    island = _island(page)
    assert island["home"]["away_from_zero"] == {"j1": "0 is outside [0.2, 1]"}
    assert island["home"]["values"]["j1"] == pytest.approx(0.6)
    assert any(note.startswith("home pose is not all zeros: j1 = 0.6") for note in island["verdict"]["notes"])
    assert 'data-home="moved"' in page
    assert all(render["configuration"]["j1"] == pytest.approx(0.6) for render in island["renders"])
    assert 'data-home="zero"' in pages["ar3"].read_text(encoding="utf-8")


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
        self.verdict: str | None = None
        self._key: str | None = None

    def handle_starttag(self, tag, attrs):
        attributes = dict(attrs)
        if tag == "html":
            self.loaded = attributes.get("data-loaded")
        self.verdict = attributes.get("data-verdict", self.verdict)
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
            from PIL import ImageChops

            content = ImageChops.difference(image.convert("RGB"), Image.new("RGB", image.size, "white")).getbbox()
            bottom = min(1400, (content[3] if content else 1400) + 16)
            image.crop((0, 0, 1200, bottom)).save(REPO / os.environ["AR3CLI_REPORT_SCREENSHOT"], optimize=True)
    dom = _chromium(pages[name], "--dump-dom", profile=tmp_path / "profile")
    parser = _Counts()
    parser.feed(dom.stdout)
    island = _island(pages[name].read_text(encoding="utf-8"))
    summary = island["summary"] if name == "lint" else island["lint"]["summary"]
    assert parser.loaded is not None, "the page's script did not run"
    assert parser.counts == {key: summary[key] for key in ("error", "warning", "info", "findings")}
    if name != "lint":
        assert parser.verdict == island["verdict"]["status"]


def _plain_page(**data) -> str:
    """robot_page on hand-made data (no pybullet): the renderer alone."""
    from ar3cli.output.html import robot_page

    return robot_page({"info": {"name": "r"}, "lint": {"summary": {}}, **data}, {"lines": data.pop("lines", {})}, [])


def test_collision_warnings_are_grouped_by_kind():
    """G1 at 100 samples: ~60 'contact only at a joint limit' infos opened the section as 60 bullets;
    now one line per kind (warnings first) with the count, the pairs one click away."""
    warnings = [{"rule": "contact-only-at-limits", "severity": "info", "message": f"a{n} - b{n} never collided ...",
                 "hint": None} for n in range(60)]
    warnings.append({"rule": "contact-at-home", "severity": "warning", "message": "x - y are in contact",
                     "hint": "usually a modelling error"})
    collisions = {"links": ["x", "y"], "samples": 100, "pairs": [], "warnings": warnings}
    page = _plain_page(collisions=collisions, lines={"collisions": ["seed 0: 100 uniform samples"]})
    groups = re.findall(r'<details class="group" data-rule="([^"]+)" data-group-count="(\d+)">', page)
    assert groups == [("contact-at-home", "1"), ("contact-only-at-limits", "60")]
    assert "60 pairs touching only at a joint limit" in page and "1 pair in contact at the home pose" in page
    shown = page.split('id="data"')[0]
    assert shown.count("never collided") == 60 and "<li>info:" not in shown


def test_the_heat_map_has_the_png_s_colours_and_letters():
    """The page's matrix and sample-collisions --png colour a pair alike (one palette)."""
    from ar3cli.collisions import heatmap_png
    from ar3cli.output.collision_palette import hex_colour
    from ar3cli.output.html_charts import heat_map_svg

    pairs = [{"link_a": "a", "link_b": "b", "category": "adjacent", "sampled": False, "fraction": 0.0, "collisions": 0},
             {"link_a": "a", "link_b": "c", "category": "default", "sampled": True, "fraction": 1.0, "collisions": 0,
              "at_home": True},
             {"link_a": "b", "link_b": "c", "category": "sometimes", "sampled": True, "fraction": 0.1, "collisions": 7},
             {"link_a": "a", "link_b": "d", "category": "never", "sampled": True, "fraction": 0.0, "collisions": 0},
             {"link_a": "b", "link_b": "d", "category": "always", "sampled": True, "fraction": 0.99, "collisions": 99}]
    svg = heat_map_svg({"links": ["a", "b", "c", "d"], "samples": 100, "pairs": pairs})
    fills = dict(re.findall(r'fill="(#[0-9a-f]{6})"[^>]*data-category="(\w+)"', svg))
    fills = {category: fill for fill, category in fills.items()}
    for category in ("adjacent", "default", "never", "always"):
        assert fills[category] == hex_colour(heatmap_png.CATEGORY_COLOURS[category]), category
    assert fills["sometimes"] == hex_colour(heatmap_png.ramp_colour(heatmap_png.scale_position(0.1)))
    letters = re.findall(r'pointer-events="none">([^<]+)</text>', svg)
    assert sorted(letters) == ["7", "A", "D", "X"]


def test_fk_s_worst_link_names_only_the_joints_that_move_it(tmp_path):
    """fk-verify's line named every joint of the robot (43 on G1); the page names the worst link's
    chain from the root (at most 8) and says how many other joints there are."""
    from ar3cli.analysis.report import fk_lines
    from ar3cli.urdf.model import load_model

    links = "".join(f'<link name="l{n}"/><link name="b{n}"/>' for n in range(12))
    chain = "".join(f'<joint name="j{n}" type="revolute"><parent link="l{n - 1}"/><child link="l{n}"/>'
                    '<limit lower="-1" upper="1" effort="1" velocity="1"/></joint>' for n in range(1, 12))
    branch = "".join(f'<joint name="k{n}" type="revolute"><parent link="{"l0" if n == 0 else f"b{n - 1}"}"/>'
                     f'<child link="b{n}"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>'
                     for n in range(12))
    robot = tmp_path / "long.urdf"
    robot.write_text(f'<robot name="long">{links}{chain}{branch}</robot>', encoding="utf-8")
    configuration = {f"j{n}": 0.5 for n in range(1, 12)} | {f"k{n}": -0.25 for n in range(12)}
    lines = fk_lines(load_model(robot), {"worst": {"link": "l11", "sample": 4, "configuration": configuration},
                                         "notes": ["a note"]})
    assert lines[0] == "note: a note"
    assert lines[1] == ("worst link: l11 (sample 4): " + ", ".join(f"j{n}=0.5" for n in range(1, 9))
                        + " and 3 more; 12 other joints are not on its path to the root")
