"""What a pull request writes cannot stall, crash or leak through the gate (issue 34): values that
overflow, names the OS refuses, meshes that are not files, globs and paths outside the tree.

Each test reproduces one report on a small file made here; every hostile file gives one finding or
one error line for itself, and the other files of the batch keep their results.
"""

from __future__ import annotations

import dataclasses
import json
import os
from pathlib import Path

import pytest

from ar3cli.lint.rules.base import LINK_INERTIAL, robot

FIFO = pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="named pipes are a POSIX feature")
GOOD = robot(f'<link name="base">{LINK_INERTIAL}<collision><geometry><box size="1 1 1"/></geometry></collision></link>')


def _json(result) -> dict:
    assert result.code in (0, 1, 2), result.stderr
    assert "internal error" not in result.stderr and "Traceback" not in result.stderr, result.stderr
    return json.loads(result.stdout)


# ---- values that overflow ------------------------------------------------------------------------

HUGE = robot(f"""
  <link name="base">{LINK_INERTIAL}<collision><geometry><sphere radius="1e200"/></geometry></collision></link>
  <link name="arm"><inertial><origin xyz="1e200 0 0"/><mass value="1e308"/>
    <inertia ixx="1e308" ixy="1e308" ixz="0" iyy="1e308" iyz="0" izz="1e308"/></inertial>
    <collision><origin xyz="1e300 0 0" rpy="inf 0 0"/><geometry><box size="1e200 1 1"/></geometry></collision></link>
  <link name="hand"><inertial><mass value="1e308"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial>
    <collision><geometry><capsule radius="1e-320" length="1e200"/></geometry></collision></link>
  <joint name="j1" type="revolute"><parent link="base"/><child link="arm"/><origin xyz="0 0 1e200"/>
    <axis xyz="1e200 0 0"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <joint name="j2" type="revolute"><parent link="arm"/><child link="hand"/><origin xyz="0 0 1"/>
    <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>""")


def test_a_value_that_overflows_is_one_file_and_the_batch_goes_on(cli, tmp_path):
    """``<sphere radius="1e200"/>`` raised OverflowError in plausibility.py (exit 3, no result for any
    other file); its siblings (squares of 1e200 m, an infinite rpy, 2**1024 in the eigenvalues, a
    total mass past the largest float) did the same in other rules and commands."""
    (tmp_path / "huge.urdf").write_text(HUGE)
    (tmp_path / "good.urdf").write_text(GOOD)
    document = _json(cli("lint-urdf", "--select", "ALL", "-f", "json", "huge.urdf", "good.urdf", cwd=tmp_path))
    assert [entry["error"] for entry in document["files"]] == [None, None]
    assert any(f["path"] == "huge.urdf" and f["rule"] == "F007" for f in document["findings"])  # inf: reported
    info = _json(cli("info", "-f", "json", "huge.urdf", cwd=tmp_path))
    assert info["total_mass_kg"] is None  # past the largest float: null, never Infinity in JSON
    _json(cli("diff", "-f", "json", "good.urdf", "huge.urdf", cwd=tmp_path))
    fixed = cli("fix-inertia", "--diff", "-f", "json", "huge.urdf", cwd=tmp_path)
    assert fixed.code in (0, 1) and "internal error" not in fixed.stderr, fixed.stderr


def test_the_largest_eigenvalues_and_huge_lengths_do_not_overflow():
    from ar3cli.maths.tensor_math import rpy_to_matrix, symmetric_eigenvalues, vector_length

    small, _, large = symmetric_eigenvalues([[1e308, 0.5e308, 0], [0.5e308, 1e308, 0], [0, 0, 1e308]])
    assert small == pytest.approx(0.5e308) and large == pytest.approx(1.5e308)
    assert symmetric_eigenvalues([[2, 1, 0], [1, 2, 0], [0, 0, 1]]) == pytest.approx((1, 1, 3))
    assert vector_length([1e200, 1e200, 0]) == pytest.approx(2 ** 0.5 * 1e200)
    assert vector_length([3.0, 4.0]) == 5.0
    assert all(value != value for row in rpy_to_matrix((float("inf"), 0, 0)) for value in row)


def test_a_rule_that_fails_on_a_file_is_that_files_error_line(tmp_path):
    """An exception in a rule (a bug) no longer ends the batch: the file's error names the rule, its
    other rules ran, and the next file is checked as usual."""
    from ar3cli.lint.engine import LintOptions, lint_file
    from ar3cli.lint.rules import REGISTRY

    def broken(ctx):
        yield from ()
        raise OverflowError("math range error")

    (tmp_path / "a.urdf").write_text(GOOD)
    options = LintOptions()
    rules = [dataclasses.replace(rule, check=broken) if rule.code == "G014" else rule for rule in options.rules()]
    result = lint_file(tmp_path / "a.urdf", rules, options)
    assert result.error is not None and result.loaded
    assert result.error.endswith("internal error in rule G014 (OverflowError: math range error), please report it; "
                                 "the other rules ran")
    assert REGISTRY["G014"].check is not broken


# ---- names the OS refuses ------------------------------------------------------------------------

def test_a_path_component_over_255_bytes_is_one_finding(cli, tmp_path):
    """ENAMETOOLONG from ``is_dir``/``is_file`` ended the batch (exit 3)."""
    long = "x" * 300
    (tmp_path / "good.urdf").write_text(GOOD)
    (tmp_path / "mesh.urdf").write_text(robot(f'<link name="base">{LINK_INERTIAL}<collision><geometry>'
                                              f'<mesh filename="{long}/m.stl"/></geometry></collision></link>'))
    (tmp_path / "package.urdf").write_text(robot(f'<link name="base">{LINK_INERTIAL}<collision><geometry>'
                                                 f'<mesh filename="package://{long}/m.stl"/></geometry></collision>'
                                                 "</link>"))
    document = _json(cli("lint-urdf", "-f", "json", f"{long}/r.urdf", "good.urdf", "mesh.urdf", "package.urdf",
                         cwd=tmp_path))
    rules = {(f["path"], f["rule"]) for f in document["findings"]}
    assert (f"{long}/r.urdf", "F001") in rules and ("mesh.urdf", "G001") in rules and ("package.urdf", "G001") in rules
    assert [entry["error"] for entry in document["files"]] == [None] * 4


# ---- meshes that are not files -------------------------------------------------------------------

@FIFO
def test_a_mesh_that_is_not_a_regular_file_is_said_so_and_left_out_of_the_sim_copy(tmp_path):
    """A FIFO mesh was "not found" (G001) and still handed to pybullet, which blocked until the
    timeout: the search stops at whatever is there, says what it is, and the copy leaves it out."""
    from ar3cli.lint.engine import LintOptions, lint_file
    from ar3cli.sim.loadable_copy import loadable_document
    from ar3cli.urdf.model import load_model

    os.mkfifo(tmp_path / "pipe.stl")
    (tmp_path / "folder.stl").mkdir()
    shapes = "".join(f'<collision><geometry><mesh filename="{name}"/></geometry></collision>'
                     for name in ("pipe.stl", "folder.stl", "/dev/null"))
    (tmp_path / "r.urdf").write_text(robot(f'<link name="base">{LINK_INERTIAL}{shapes}</link>'))
    model = load_model(tmp_path / "r.urdf")
    kinds = [shape.geometry.resolution.problem for shape in model.links[0].collisions]
    assert kinds == ["not a regular file (a FIFO)", "not a regular file (a folder)", "not a regular file (a device)"]
    assert b"<collision" not in loadable_document(model)
    options = LintOptions()
    messages = [f.message for f in lint_file(tmp_path / "r.urdf", options.rules(), options).findings if f.rule == "G001"]
    assert len(messages) == 3 and "mesh pipe.stl: not a regular file (a FIFO)" in messages[0]


# ---- listing and paths outside the tree ----------------------------------------------------------

XACRO = '<?xml version="1.0"?>\n<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">\n{}\n</robot>\n'


def _xacro_findings(cli, folder: Path, **files: str) -> dict[str, str]:
    for name, body in files.items():
        (folder / f"{name}.xacro").write_text(XACRO.format(body))
    document = _json(cli("lint-urdf", "-f", "json", *(f"{name}.xacro" for name in files), cwd=folder))
    return {f["path"].removesuffix(".xacro"): f["message"] for f in document["findings"] if f["rule"] == "F004"}


def test_an_include_glob_outside_the_tree_is_refused_by_its_pattern(cli, tmp_path):
    """``<xacro:include filename="/root/.b*"/>`` answered "xacro may not read /root/.bashrc": each
    glob revealed a name. A pattern outside the roots is refused as written, whatever is there; a
    match leading out through a symlinked folder inside the tree is left out, as if absent."""
    outside = tmp_path / "outside"
    outside.mkdir()
    (outside / ".secret_name.xacro").write_text(XACRO.format(""))
    repo = tmp_path / "repo"
    (repo / "parts").mkdir(parents=True)
    (repo / "parts" / "arm.xacro").write_text(XACRO.format('<link name="arm"/>'))
    (repo / "parts" / "out").symlink_to(outside, target_is_directory=True)
    refused = _xacro_findings(cli, repo, a=f'<xacro:include filename="{outside}/.s*"/>',
                              b=f'<xacro:include filename="{outside}/.nothing*"/>',
                              c='<xacro:include filename="parts/*/../../../outside/.s*"/>',
                              d='<xacro:include filename="parts/out/.secret_name.xacro"/>',
                              e='<xacro:include filename="parts/out/.no_such_name.xacro"/>',
                              f='<link name="$(cwd)"/>')
    assert refused["a"] == (f"xacro error: xacro may not list {outside}/.s*: it is outside the robot's folder and "
                            "packages (safe mode; pass --package-path NAME=DIR for a package, or pass --xacro trusted "
                            "only for files you trust)")
    assert refused["b"] == refused["a"].replace(".s*", ".nothing*")  # the same answer, match or not
    assert "may not climb with '..' after a wildcard" in refused["c"]
    assert refused["d"].replace(".secret_name", ".no_such_name") == refused["e"]  # existence not told
    assert refused["f"].startswith("xacro error: $(cwd): xacro may not read the working folder's path")
    assert all("secret_name" not in message or key == "d" for key, message in refused.items())
    globbed = _xacro_findings(cli, repo, g='<xacro:include filename="parts/*.xacro"/>'
                                           '<xacro:include filename="parts/*/*.xacro"/>')
    assert globbed == {}  # the first matches arm.xacro; the second only what lies outside: nothing


def test_places_searched_outside_the_tree_are_counted_not_named(cli, tmp_path):
    """G001's "looked in" listed every folder up to / (the runner's layout): only places inside the
    current folder or the robot's folder are named, the others counted."""
    repo = tmp_path / "work" / "repo"
    repo.mkdir(parents=True)
    (repo / "r.urdf").write_text(robot(f'<link name="base">{LINK_INERTIAL}<collision><geometry>'
                                       '<mesh filename="package://nopkg/m.stl"/></geometry></collision></link>'))
    document = _json(cli("lint-urdf", "-f", "json", "r.urdf", cwd=repo))
    [finding] = [f for f in document["findings"] if f["rule"] == "G001"]
    message, hint = finding["message"], finding["hint"]
    assert str(tmp_path) not in message + hint and "/work/" not in message + hint, (message, hint)
    assert message.endswith("looked in ancestors of the robot's folder named nopkg or with package.xml "
                            f"<name>nopkg</name> and {len(repo.parents) + 1} more places")  # the hint: every one
    assert hint.endswith("Looked in: ancestors of the robot's folder named nopkg or with package.xml "
                         f"<name>nopkg</name>; nopkg/m.stl; {len(repo.parents)} places outside the robot's folder.")


# ---- no secret on the page -----------------------------------------------------------------------

SECRET = "aws_secret_access_key = hunter2-do-not-show"


def test_a_symlinked_robot_file_leading_out_of_its_folder_is_never_shown(cli, tmp_path):
    """``ln -s ~/.aws/credentials robot.urdf; lint-urdf --format html robot.urdf`` showed the secret
    (F002's cited lines were read back from the file); so did ``/proc/self/environ``. A file named on
    the command line is still linted as asked; its lines are shown only when it lies in its own
    folder, and only as the bytes that were parsed."""
    outside = tmp_path / "home" / ".aws"
    outside.mkdir(parents=True)
    (outside / "credentials").write_text(f"[default]\n{SECRET}\n")
    repo = tmp_path / "repo"
    repo.mkdir()
    (repo / "robot.urdf").symlink_to(outside / "credentials")
    (repo / "environ.urdf").symlink_to("/proc/self/environ")
    (repo / "own.urdf").write_text(GOOD.replace("</robot>", "<bad></robot>"))  # F002 on a file of the tree
    result = cli("lint-urdf", "--format", "html", "robot.urdf", "environ.urdf", "own.urdf", cwd=repo,
                 env={"AR3CLI_TEST_SECRET": SECRET})
    assert result.code == 1, result.stderr
    assert "hunter2" not in result.stdout and "AR3CLI_TEST_SECRET" not in result.stdout
    assert result.stdout.count("F002") >= 3  # each is still a finding
    assert "&lt;bad&gt;" in result.stdout  # the tree's own file keeps its cited lines


def test_cited_lines_are_only_the_bytes_that_were_parsed(tmp_path):
    from ar3cli.commands.finding_context import finding_context
    from ar3cli.findings import Finding, Severity

    path = tmp_path / "r.urdf"
    path.write_text("<robot>\n<link/>\n</robot>\n")
    finding = Finding("S001", Severity.ERROR, "m", str(path), 2, 1, "")
    import hashlib

    digest = hashlib.sha256(path.read_bytes()).hexdigest()
    assert finding_context([finding], {str(path): digest})["sources"][str(path)][2] == "<link/>"
    assert finding_context([finding], {})["sources"] == {}  # not a file the linter may show
    path.write_text(f"<robot>\n{SECRET}\n</robot>\n")  # replaced after it was linted
    assert finding_context([finding], {str(path): digest})["sources"] == {}


def test_a_folder_search_leaves_out_links_leading_out_of_it(cli, tmp_path):
    outside = tmp_path / "outside"
    outside.mkdir()
    (outside / "secret.urdf").write_text(GOOD)
    robots = tmp_path / "repo" / "robots"
    robots.mkdir(parents=True)
    (robots / "good.urdf").write_text(GOOD)
    (robots / "inside.urdf").symlink_to("good.urdf")
    (robots / "out.urdf").symlink_to(outside / "secret.urdf")
    result = cli("lint-urdf", "-f", "json", "robots", cwd=tmp_path / "repo")
    assert [entry["path"] for entry in json.loads(result.stdout)["files"]] == ["robots/good.urdf", "robots/inside.urdf"]
    assert result.stderr.splitlines() == ["ar3cli: note: skipped 1 symbolic link to a file outside the folder "
                                          "searched (robots/out.urdf); name a file as PATH to lint it"]
    named = cli("lint-urdf", "-f", "json", "robots/out.urdf", cwd=tmp_path / "repo")
    assert [entry["path"] for entry in json.loads(named.stdout)["files"]] == ["robots/out.urdf"]


# ---- the same file by many paths -----------------------------------------------------------------

def test_a_mesh_reached_by_many_paths_is_read_once(tmp_path, monkeypatch):
    """Two links ``a -> .`` and ``b -> .`` and 120 paths to one 20 MB OBJ (``a/b/a/m.obj``...) took
    207 s of static lint: the mesh caches were keyed by the path. Now by the file's identity too."""
    import itertools

    from ar3cli.infra import file_cache
    from ar3cli.lint.engine import LintOptions, lint_file
    from ar3cli.urdf import meshinfo

    monkeypatch.setenv("AR3CLI_NO_CACHE", "1")
    for name in ("_DISK_CACHE", "_CONTENT_CACHE", "_HULL_CACHE"):
        old = getattr(meshinfo, name)
        monkeypatch.setattr(meshinfo, name, file_cache.FileFacts(old.name, old.version))
    meshinfo._mesh_bounds.cache_clear()
    (tmp_path / "m.obj").write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 2 4\nf 1 3 4\nf 2 3 4\n")
    (tmp_path / "a").symlink_to(".")
    (tmp_path / "b").symlink_to(".")
    paths = ["/".join(combo) + "/m.obj" for depth in (1, 2, 3, 4) for combo in itertools.product("ab", repeat=depth)]
    shapes = "".join(f'<collision><geometry><mesh filename="{path}"/></geometry></collision>' for path in paths)
    (tmp_path / "r.urdf").write_text(robot(f'<link name="base">{LINK_INERTIAL}{shapes}</link>'))
    reads = []
    original = meshinfo.read_mesh
    monkeypatch.setattr(meshinfo, "read_mesh", lambda path: reads.append(path) or original(path))
    options = LintOptions()
    result = lint_file(tmp_path / "r.urdf", options.rules(), options)
    assert result.error is None and len(paths) == 30
    assert meshinfo._mesh_bounds.cache_info().currsize == 1 and len(reads) <= 2  # bounds, and the OBJ's statements


# ---- every file's check within time and memory ---------------------------------------------------

def test_one_files_check_past_its_time_or_memory_is_one_line_and_the_batch_goes_on(tmp_path, monkeypatch):
    """A single file was linted in ar3cli's own process, under no limit: a 6 KB xacro macro called
    200 times grew past 6 GB and died with exit 3. Every file is now checked in a forked process with
    the limits of every child (``--timeout`` per file, the memory cap): past either, the file gets one
    line, and the other files their findings."""
    import time

    from ar3cli.infra import child_limits
    from ar3cli.lint import engine

    def greedy(ctx):
        if ctx.model.path.name == "hungry.urdf":
            yield from ()
            bytearray(8 << 30)  # more than any child may map
        if ctx.model.path.name == "slow.urdf":
            time.sleep(60)
        yield from ()

    options = engine.LintOptions()
    rules = [dataclasses.replace(rule, check=greedy) if rule.code == "G014" else rule for rule in options.rules()]
    monkeypatch.setattr(engine.LintOptions, "rules", lambda self: rules)
    monkeypatch.setenv(child_limits.MEMORY_VARIABLE, "1024")
    monkeypatch.setattr(child_limits, "_timeout", 3.0)
    for name in ("hungry", "slow", "good"):
        (tmp_path / f"{name}.urdf").write_text(GOOD)
    results = engine.lint_paths([tmp_path / f"{name}.urdf" for name in ("hungry", "slow", "good")], options,
                                use_cache=False, jobs=2)
    hungry, slow, good = results
    assert hungry.error.endswith("hungry.urdf: checking it ran out of memory (the limit of a child process is 1 GB "
                                 "more than it starts with; set AR3CLI_CHILD_MEMORY_MB to change it)")
    assert slow.error.endswith("slow.urdf: checking it took longer than the limit of 3 s per file; raise --timeout "
                               "(0: no limit) if the file is just large")
    assert good.error is None and good.loaded


def test_a_file_whose_findings_flood_the_output_is_one_line(tmp_path, monkeypatch):
    from ar3cli.lint import engine

    monkeypatch.setattr(engine, "MAX_FINDINGS_TEXT", 10_000)
    names = "".join(f'<link name="orphan_{index}"/>' for index in range(300))
    (tmp_path / "orphans.urdf").write_text(robot(names))
    (tmp_path / "good.urdf").write_text(GOOD)
    options = engine.LintOptions()
    flood, good = engine.lint_paths([tmp_path / "orphans.urdf", tmp_path / "good.urdf"], options, use_cache=False)
    assert flood.findings == [] and "more than ar3cli reports for one file" in flood.error
    assert good.error is None


@pytest.mark.parametrize(("command", "stage"), [(["info"], "summarising it"), (["diff", "old.urdf"], "comparing it"),
                                                (["fix-joints", "--diff"], "linting the fixed file")])
def test_in_process_work_on_a_file_has_the_limits_of_every_child(cli, tmp_path, command, stage):
    """diff, info, report's summary and a fix's lint of its result ran in ar3cli's own process, under
    no limit (a 1,000-child renamed star kept diff busy for half a minute, in the Action's diff step):
    each runs in a child with the command's --timeout and the memory cap."""
    from ar3cli.lint.rules.base import arm

    text = arm().replace('<axis xyz="0 0 1"/>', '<axis xyz="0 0 2"/>')  # J010: fix-joints has work to do
    (tmp_path / "old.urdf").write_text(text)
    (tmp_path / "new.urdf").write_text(text)
    result = cli(*command, "new.urdf", "--timeout", "0.001", cwd=tmp_path)
    assert result.code == 2, result.stdout + result.stderr
    assert result.stderr.splitlines()[-1] == (f"ar3cli: error: new.urdf: timed out after 0.001 s while {stage}; "
                                              "raise --timeout (0: no limit) if the file is just large")
