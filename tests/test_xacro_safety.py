"""xacro on untrusted input (issue 22): safe mode runs no code, reads only the robot's files, no
environment, bounded work; ``--xacro trusted`` is plain xacro. Every attack is a small file made here."""

from __future__ import annotations

import json
import math
import os
from pathlib import Path

import pytest

from ar3cli.errors import UserError
from ar3cli.urdf import xacro_expand
from ar3cli.urdf.packages import PackageResolver
from ar3cli.urdf.xacro_eval import BUILTINS, MATH, Refused, evaluate
from ar3cli.urdf.xacro_safe import XacroPolicy
from tests.conftest import REPO

HEAD = '<?xml version="1.0"?>\n<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">\n'


def _xacro(folder: Path, body: str, name: str = "robot.urdf.xacro") -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / name
    path.write_text(HEAD + body + "\n</robot>\n")
    return path


def _expand(path: Path, args: dict[str, str] | None = None, policy: XacroPolicy | None = None) -> bytes:
    before = xacro_expand.current_policy()
    xacro_expand.set_policy(policy or XacroPolicy())
    try:
        return xacro_expand.expand(path, args or {}, PackageResolver(path.parent, {}))
    finally:
        xacro_expand.set_policy(before)


def _refusal(path: Path, **kwargs) -> str:
    with pytest.raises(UserError) as caught:
        _expand(path, **kwargs)
    message = caught.value.message
    assert "\n" not in message and message.startswith(f"{path}: xacro error: ")
    return message


# --- code execution -------------------------------------------------------------------------------

def _rce(tmp_path: Path) -> tuple[Path, Path]:
    marker = tmp_path / "pwned"
    path = _xacro(tmp_path / "robot", f"""
 <xacro:property name="subs" value="${{python.vars(python.type)['_'+'_subclasses_'+'_'](python.int.mro()[-1])}}"/>
 <xacro:property name="cw" value="${{[c for c in subs if 'catch_warnings' in python.str(c)][0]}}"/>
 <link name="base${{cw()._module.sys.modules['os'].system('touch {marker}')}}"/>""")
    return path, marker


@pytest.mark.parametrize("command", ["lint-urdf", "info"])
def test_the_subclasses_escape_runs_nothing(cli, tmp_path, command):
    path, marker = _rce(tmp_path)
    result = cli(command, "--no-cache", str(path)) if command == "lint-urdf" else cli(command, str(path))
    assert not marker.exists()
    assert "safe xacro refuses" in result.stdout + result.stderr
    assert result.code == (1 if command == "lint-urdf" else 2)  # lint: an F004 finding; info: a one-line error
    if command == "lint-urdf":
        assert "F004" in result.stdout


def test_trusted_mode_is_plain_xacro(tmp_path):
    path, marker = _rce(tmp_path)
    _expand(path, policy=XacroPolicy(trusted=True))
    assert marker.exists()  # what --xacro trusted gives up, shown once


def test_trusted_option_reaches_the_expansion(cli, tmp_path):
    path = _xacro(tmp_path / "robot", '<link name="n_${python.len([1, 2])}"/>')
    assert "python namespace" in cli("info", str(path)).stderr
    trusted = cli("info", "--xacro", "trusted", "--format", "json", str(path))
    assert trusted.code == 0 and "n_2" in trusted.stdout


def test_trusted_option_reaches_the_report_lint_section(cli, tmp_path):
    """report's lint section reads the xacro as the rest of the page does: with ``--xacro trusted``
    it is expanded, not refused (an F004 on the page for a file the page then drew)."""
    path = _xacro(tmp_path / "robot", '<link name="n_${python.len([1, 2])}"/>')
    page = tmp_path / "page.html"
    result = cli("report", "--xacro", "trusted", "--samples", "1", "-o", str(page), "--format", "json", str(path))
    assert result.code == 0, result.stderr
    assert json.loads(result.stdout)["lint"]["error"] == 0 and "F004" not in page.read_text()


def test_eval_substitution_runs_nothing(tmp_path):
    marker = tmp_path / "pwned"
    path = _xacro(tmp_path / "robot", f"""
 <xacro:property name="p" value="open('{marker}', 'w').close()"/>
 <link name="a$(eval ${{p}})"/>""")
    message = _refusal(path)
    assert not marker.exists() and "name 'open' is not defined" in message


# --- leaks ----------------------------------------------------------------------------------------

def test_load_yaml_outside_the_robot_folder_is_refused(tmp_path):
    secret = tmp_path / "secret.yaml"
    secret.write_text("token: hunter2\n")
    path = _xacro(tmp_path / "robot", f'<link name="a_${{xacro.load_yaml(\'{secret}\')}}"/>')
    message = _refusal(path)
    assert "outside the robot's folder and packages" in message and "hunter2" not in message


def test_include_outside_the_robot_folder_or_through_a_symlink_is_refused(tmp_path):
    outside = _xacro(tmp_path / "elsewhere", '<link name="x"/>', "parts.xacro")
    robot = tmp_path / "robot"
    path = _xacro(robot, f'<xacro:include filename="{outside}"/>')
    assert "outside the robot's folder" in _refusal(path)
    (robot / "link.xacro").symlink_to(outside)
    linked = _xacro(robot, '<xacro:include filename="link.xacro"/>', "linked.urdf.xacro")
    assert "outside the robot's folder" in _refusal(linked)


def test_yaml_and_includes_inside_the_tree_work_like_xacro(tmp_path):
    robot = tmp_path / "robot"
    (robot / "config").mkdir(parents=True)
    (robot / "config" / "arm.yaml").write_text("arm:\n  mass: 2.5\n  angle: !degrees 90\nlinks: [a, b]\n")
    _xacro(robot / "parts", '<xacro:macro name="part" params="n"><link name="${n}"/></xacro:macro>', "part.xacro")
    path = _xacro(robot, """
 <xacro:include filename="parts/part.xacro"/>
 <xacro:property name="cfg" value="${xacro.load_yaml('config/arm.yaml')}"/>
 <xacro:part n="m_${cfg.arm.mass}_${cfg['arm']['angle']}_${cfg.links[1]}"/>""")
    assert _expand(path) == _expand(path, policy=XacroPolicy(trusted=True))
    assert f'name="m_2.5_{math.pi / 2}_b"'.encode() in _expand(path)


def test_environment_is_refused_unless_allowed(tmp_path, monkeypatch):
    monkeypatch.setenv("CI_TOKEN", "s3cret")
    path = _xacro(tmp_path / "robot", '<link name="b_$(optenv CI_TOKEN fallback)"/>')
    message = _refusal(path)
    assert "--xacro-env CI_TOKEN" in message and "s3cret" not in message
    assert "--xacro-env HOME" in _refusal(_xacro(tmp_path / "robot", '<link name="b_$(env HOME)"/>', "home.xacro"))
    allowed = _expand(path, policy=XacroPolicy(env=frozenset({"CI_TOKEN"})))
    assert b'name="b_s3cret"' in allowed


def test_xacro_env_option_reaches_the_expansion(cli, tmp_path):
    path = _xacro(tmp_path / "robot", '<link name="b_$(optenv AR3CLI_TEST_NAME none)"/>')
    refused = cli("info", str(path))
    assert refused.code == 2 and "--xacro-env AR3CLI_TEST_NAME" in refused.stderr
    allowed = cli("info", "--xacro-env", "AR3CLI_TEST_NAME", "--format", "json", str(path),
                  env={**os.environ, "AR3CLI_TEST_NAME": "seen"})
    assert allowed.code == 0 and "b_seen" in allowed.stdout


# --- bounded work ---------------------------------------------------------------------------------

def test_including_a_device_or_a_fifo_is_refused_at_once(tmp_path):
    assert "outside the robot's folder" in _refusal(_xacro(tmp_path / "robot", '<xacro:include filename="/dev/zero"/>'))
    fifo = tmp_path / "robot" / "parts.xacro"
    os.mkfifo(fifo)
    assert "not a regular file" in _refusal(_xacro(tmp_path / "robot", '<xacro:include filename="parts.xacro"/>',
                                                  "fifo.urdf.xacro"))


def test_huge_numbers_and_strings_are_refused(tmp_path):
    assert "a power over" in _refusal(_xacro(tmp_path, '<link name="${9**9**9}"/>'))
    assert "repetition" in _refusal(_xacro(tmp_path, "<link name=\"${'a' * 10**9}\"/>", "s.xacro"))


def test_a_macro_bomb_stops_at_the_time_limit(tmp_path, monkeypatch):
    monkeypatch.setattr(xacro_expand, "WALL_SECONDS", 1)
    monkeypatch.setattr(xacro_expand, "CPU_SECONDS", 1)
    macros = ['<xacro:macro name="m0"><link name="l"/></xacro:macro>']
    macros += [f'<xacro:macro name="m{i}"><xacro:m{i - 1}/><xacro:m{i - 1}/></xacro:macro>' for i in range(1, 29)]
    message = _refusal(_xacro(tmp_path, "\n".join(macros) + "\n<xacro:m28/>"))
    assert "limit" in message


# --- the evaluator --------------------------------------------------------------------------------

_NAMES = {"a": 3, "s": "ab", "xs": [1, 2, 3], "d": {"k": 1.5}, "flag": True}


def _lookup(name: str):
    known = {**BUILTINS, **MATH, **_NAMES}
    if name not in known:
        raise NameError(f"name '{name}' is not defined")
    return known[name]


@pytest.mark.parametrize("expression", [
    "1 + 2 * 3 - 4 / 5", "7 // 2 % 3", "2 ** 10", "-a", "not flag", "a > 2 and a < 5", "1 < a <= 3 != 4",
    "s + 'c'", "s * 3", "xs[1:]", "xs[-1]", "d['k']", "[1, (2, 3), {'x': a}]", "'x' if flag else 'y'",
    "pi / 2", "sin(radians(30))", "sqrt(2) * cos(pi)", "atan2(1, 1)", "round(2.567, 2)", "max(xs) + min(1, 2)",
    "len(s)", "str(a) + s", "float('1.5')", "int(3.9)", "sorted([3, 1, 2])", "list(range(3))", "a in xs",
    "abs(-2)", "degrees(pi)", "fabs(-1.0)", "a | 4", "a ^ 1", "1 << 3", "True or x", "0 and x",
])
def test_allowed_expressions_equal_python(expression):
    python = eval(expression, {"__builtins__": {}}, {**{n: getattr(math, n) for n in dir(math) if not n.startswith("_")},
                                                    **{n: __builtins__[n] for n in ("len", "str", "float", "int",
                                                       "round", "max", "min", "sorted", "list", "range", "abs")},
                                                    **_NAMES})
    assert evaluate(expression, _lookup) == python


@pytest.mark.parametrize("expression, what", [
    ("s.upper()", "attribute access"), ("__import__", "the name '__import__'"), ("python.len(s)", "python namespace"),
    ("[c for c in xs]", "comprehension"), ("(lambda: 1)()", "lambda"), ("f'{a}'", "f-string"),
    ("'%s' % a", "%-formatting"), ("9 ** 9 ** 9", "power"), ("2 << 100000", "shift"), ("'ab' * 10 ** 8", "repetition"),
    ("max(*xs)", "unpacking"), ("{1, 2}", "set literal"), ("(x := 1)", "assignment"), ("factorial(10 ** 5)", "factorial"),
    ("b'x'", "bytes"), ("(1).real", "attribute access"), ("xs.__class__", "attribute '__class__'"),
    ("[[0] * 1000] * 1001", "nested ones counted"), ("round(1, -10 ** 9)", "round()"), ("sum([xs], [])", "sum()"),
])
def test_refused_expressions(expression, what):
    with pytest.raises(Refused, match="safe xacro refuses") as caught:
        evaluate(expression, _lookup)
    assert what in str(caught.value)


def test_unknown_names_and_bad_expressions_fail_as_in_python():
    with pytest.raises(NameError, match="name 'nope' is not defined"):
        evaluate("nope + 1", _lookup)
    with pytest.raises(ZeroDivisionError):
        evaluate("1 / 0", _lookup)
    with pytest.raises(SyntaxError):
        evaluate("1 +", _lookup)


# --- the same robot in both modes, arguments --------------------------------------------------------

@pytest.mark.parametrize("fixture", [REPO / "tests" / "data" / "xacro" / "arm.urdf.xacro",
                                     REPO / "assets" / "ar3" / "ar3.urdf.xacro",
                                     REPO / "tests" / "data" / "xacro_features" / "features.urdf.xacro"])
def test_fixtures_expand_identically_in_both_modes(fixture):
    assert _expand(fixture) == _expand(fixture, policy=XacroPolicy(trusted=True))


def test_arguments_features_identical_in_both_modes(tmp_path):
    path = _xacro(tmp_path, """
 <xacro:arg name="n" default="2"/>
 <xacro:property name="w" value="${radians(90) * $(arg n)}"/>
 <xacro:property name="items" value="${[1, 2, 3]}"/>
 <xacro:if value="${w > 1 and len(items) == 3}"><link name="if_${items[-1]}"/></xacro:if>
 <link name="l_${w}_$(eval n * 2 + pi)_${xacro.arg('n')}_${'y' if w else 'n'}_${math.pi:.3}"/>""".replace(
        "${math.pi:.3}", "${round(math.pi, 3)}"))
    assert _expand(path, {"n": "3"}) == _expand(path, {"n": "3"}, policy=XacroPolicy(trusted=True))


def test_a_failure_of_a_file_with_arguments_names_them(tmp_path):
    path = _xacro(tmp_path, """
 <xacro:arg name="robot_type" default="none"/>
 <xacro:include filename="$(arg robot_type)/SE4_$(arg robot_type)/robot.xacro"/>""")
    message = _refusal(path)
    assert "cannot read" in message and "robot_type" in message and "--xacro-arg NAME:=VALUE" in message


def test_the_action_and_the_hooks_use_safe_mode():
    for name in ("action.yml", ".pre-commit-hooks.yaml"):
        assert "trusted" not in (REPO / name).read_text()
