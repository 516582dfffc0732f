"""The GitHub Action (action.yml) is well formed and works: its ``run:`` steps are executed here with bash.

The runner is imitated just enough: ``${{ ... }}`` expressions (inputs, steps, runner, github and the
status functions) are evaluated, each step gets its own ``$GITHUB_OUTPUT`` and ``if:`` decides whether
it runs. ``uses:`` steps are not executed (no network): actions/setup-python answers with this
interpreter, and the upload step is only checked for whether it would run and with what. The install
step is not executed either (ar3cli is installed here): a wrapper stands where it would put ar3cli.
"""

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
from dataclasses import dataclass, field
from pathlib import Path

import pytest
import yaml

from tests.conftest import ASSETS, REPO

ACTION = REPO / "action.yml"
EXPRESSION = re.compile(r"\$\{\{(.*?)\}\}", re.DOTALL)
TOKEN = re.compile(r"\s*(?:(?P<string>'(?:[^']|'')*')|(?P<op>&&|\|\||==|!=|!|\(|\))|(?P<call>[a-z]+\(\))"
                   r"|(?P<name>[A-Za-z_][\w.-]*))")


def _action() -> dict:
    return yaml.safe_load(ACTION.read_text(encoding="utf-8"))


def _expressions(node) -> list[str]:
    """Every ``${{ ... }}`` expression in a loaded YAML tree (the ``if:`` values are expressions too)."""
    if isinstance(node, dict):
        return [found for key, value in node.items()
                for found in (_expressions(value) + ([value] if key == "if" and "${{" not in value else []))]
    if isinstance(node, list):
        return [found for item in node for found in _expressions(item)]
    return [match.strip() for match in EXPRESSION.findall(node)] if isinstance(node, str) else []


def _names(expression: str) -> list[str]:
    return [match.group("name") for match in TOKEN.finditer(expression) if match.group("name")]


def evaluate(expression: str, context: dict, status: dict):
    """A GitHub expression (the subset action.yml uses) translated to Python and evaluated."""
    python, position = [], 0
    expression = expression.strip()
    while position < len(expression):
        match = TOKEN.match(expression, position)
        assert match and match.end() > position, f"cannot parse {expression[position:]!r}"
        position = match.end()
        if match.group("string"):
            python.append(repr(match.group("string")[1:-1].replace("''", "'")))
        elif match.group("op"):
            python.append({"&&": " and ", "||": " or ", "!": " not "}.get(match.group("op"), match.group("op")))
        elif match.group("call"):
            python.append(repr(status[match.group("call")[:-2]]))
        else:
            value = context
            for part in match.group("name").split("."):
                value = value.get(part, "") if isinstance(value, dict) else ""
            python.append(repr(value))
    return eval("".join(python), {"__builtins__": {}})  # noqa: S307 - only literals and operators


def substitute(text: str, context: dict, status: dict) -> str:
    return EXPRESSION.sub(lambda match: str(evaluate(match.group(1), context, status)), text)


@dataclass
class ActionRun:
    outputs: dict
    steps: dict
    stdout: str = ""
    stderr: str = ""
    summary: str = ""
    workspace: Path = Path()
    would_use: dict = field(default_factory=dict)

    @property
    def failed(self) -> bool:
        return any(step["outcome"] == "failure" for step in self.steps.values())


def run_action(workspace: Path, tmp_path: Path, github: dict | None = None, **inputs: str) -> ActionRun:
    """Run action.yml's steps as a composite action would, in ``workspace``, with these inputs
    (``github``: more of the github context, such as the pull request's ``event``)."""
    action = _action()
    declared = action["inputs"]
    assert set(inputs) <= set(declared), f"undeclared inputs {set(inputs) - set(declared)}"
    runner_temp = tmp_path / "runner-temp"
    runner_temp.mkdir()
    summary = tmp_path / "step_summary.md"
    summary.touch()
    context = {"inputs": {name: str(spec.get("default", "")) for name, spec in declared.items()} | inputs,
               "github": {"action_path": str(REPO), "workspace": str(workspace), **(github or {})},
               "runner": {"temp": str(runner_temp), "os": "Linux"},
               "steps": {}}
    result = ActionRun(outputs={}, steps=context["steps"], workspace=workspace)
    for index, step in enumerate(action["runs"]["steps"]):
        step_id = step.get("id", f"__{index}")
        failed = any(done["outcome"] == "failure" for done in context["steps"].values())
        status = {"success": not failed, "failure": failed, "always": True, "cancelled": False}
        condition = str(step.get("if", "success()"))
        condition = EXPRESSION.sub(lambda match: match.group(1), condition)
        if not evaluate(condition, context, status):
            context["steps"][step_id] = {"outcome": "skipped", "outputs": {}}
            continue
        env = {name: substitute(str(value), context, status) for name, value in step.get("env", {}).items()}
        if "uses" in step:
            with_ = {name: substitute(str(value), context, status) for name, value in step.get("with", {}).items()}
            result.would_use[step["uses"].split("@")[0]] = with_
            outputs = {"python-path": sys.executable} if step["uses"].startswith("actions/setup-python@") else {}
            context["steps"][step_id] = {"outcome": "success", "outputs": outputs}
            continue
        assert step["shell"] == "bash", f"step {step_id}: composite run steps need shell: bash"
        if step_id == "install":
            _check_install_step(step, env)
            _fake_install(Path(env["AR3CLI_VENV"]))
            context["steps"][step_id] = {"outcome": "success", "outputs": {}}
            continue
        script = tmp_path / f"step-{step_id}.sh"
        script.write_text(substitute(step["run"], context, status), encoding="utf-8")
        output_file = tmp_path / f"output-{step_id}.txt"
        output_file.touch()
        environment = {**os.environ, "PYTHONPATH": str(REPO), "NO_COLOR": "1", "RUNNER_OS": "Linux",
                       "RUNNER_TEMP": str(runner_temp), "GITHUB_ACTION_PATH": str(REPO),
                       "GITHUB_WORKSPACE": str(workspace), "GITHUB_ACTIONS": "true",
                       "GITHUB_STEP_SUMMARY": str(summary), "GITHUB_OUTPUT": str(output_file), **env}
        # GitHub's own command line for `shell: bash`
        done = subprocess.run(["bash", "--noprofile", "--norc", "-eo", "pipefail", str(script)], cwd=workspace,
                              env=environment, capture_output=True, text=True, timeout=120, stdin=subprocess.DEVNULL)
        result.stdout += done.stdout
        result.stderr += done.stderr
        outputs = dict(line.split("=", 1) for line in output_file.read_text(encoding="utf-8").splitlines() if line)
        context["steps"][step_id] = {"outcome": "success" if done.returncode == 0 else "failure", "outputs": outputs}
    status = {"success": not result.failed, "failure": result.failed, "always": True, "cancelled": False}
    result.outputs = {name: substitute(str(spec["value"]), context, status)
                      for name, spec in action.get("outputs", {}).items()}
    result.summary = summary.read_text(encoding="utf-8")
    return result


def _check_install_step(step: dict, env: dict) -> None:
    """The install step pip-installs the action's own checkout (or the ``package`` input) into a venv."""
    run = step["run"]
    assert env["AR3CLI_ACTION_PATH"] == str(REPO)
    assert env["AR3CLI_PYTHON"] == sys.executable
    assert re.search(r'"\$AR3CLI_VENV/bin/python" -m pip install .*"\$\{AR3CLI_PACKAGE:-\$AR3CLI_ACTION_PATH\}"', run)
    assert '-m venv "$AR3CLI_VENV"' in run


def _fake_install(venv: Path) -> None:
    """What the install step leaves behind, for ar3cli from this checkout: ``VENV/bin/ar3cli``."""
    wrapper = venv / "bin" / "ar3cli"
    wrapper.parent.mkdir(parents=True)
    wrapper.write_text(f'#!/bin/sh\nexec "{sys.executable}" -m ar3cli "$@"\n', encoding="utf-8")
    wrapper.chmod(0o755)


@pytest.fixture
def robots(tmp_path) -> Path:
    """A workspace with robots/: the bundled AR3 (clean) and the AR3 with three links missing <inertial>."""
    workspace = tmp_path / "workspace"
    (workspace / "robots").mkdir(parents=True)
    shutil.copy(ASSETS / "ar3" / "ar3.urdf", workspace / "robots" / "good.urdf")
    shutil.copy(ASSETS / "examples" / "ar3_no_inertia.urdf", workspace / "robots" / "broken.urdf")
    return workspace


# -- structure ----------------------------------------------------------------------------------------------


def test_action_is_a_composite_action_with_declared_inputs_and_outputs():
    action = _action()
    assert action["runs"]["using"] == "composite"
    assert action["name"] and action["description"]
    inputs, outputs, steps = action["inputs"], action["outputs"], action["runs"]["steps"]
    assert {"paths", "args", "fail-on", "sarif", "upload-sarif"} <= set(inputs)
    assert inputs["paths"]["default"] == "."
    assert {"exit-code", "failed", "sarif-file"} <= set(outputs)
    for name, spec in {**inputs, **outputs}.items():
        assert spec.get("description"), f"{name} has no description"
    for spec in inputs.values():  # inputs reach the steps as strings: defaults must be strings too
        assert isinstance(spec.get("default", ""), str)
    step_ids = [step.get("id") for step in steps]
    for step in steps:
        assert ("uses" in step) != ("run" in step)
        if "run" in step:
            assert step["shell"] == "bash"
            assert "${{" not in step["run"], "inputs reach the scripts through env:, never spliced into the code"
    for expression in _expressions(action):
        for name in _names(expression):
            root, _, rest = name.partition(".")
            assert root in ("inputs", "steps", "runner", "github"), f"unknown context in {expression!r}"
            if root == "inputs":
                assert rest in inputs, f"${{{{ {name} }}}} is not a declared input"
            if root == "steps":
                assert rest.split(".")[0] in step_ids, f"{name}: no step with that id"
    for spec in outputs.values():
        assert re.fullmatch(r"\$\{\{ steps\.[\w-]+\.outputs\.[\w-]+ \}\}", spec["value"])


def test_install_step_pip_installs_the_actions_own_checkout():
    install = next(step for step in _action()["runs"]["steps"] if step.get("id") == "install")
    assert install["env"]["AR3CLI_ACTION_PATH"] == "${{ github.action_path }}"
    assert install["env"]["AR3CLI_PACKAGE"] == "${{ inputs.package }}"
    assert "pip install" in install["run"] and "$AR3CLI_ACTION_PATH" in install["run"]
    setup = next(step for step in _action()["runs"]["steps"] if step.get("uses", "").startswith("actions/setup-python@"))
    assert setup["with"]["update-environment"] is False, "the job's own Python must stay untouched"


def test_expression_evaluator():
    context = {"inputs": {"sarif": "", "upload-sarif": "true"}, "steps": {"sarif": {"outcome": "success"}}}
    status = {"cancelled": False}
    assert evaluate("inputs.sarif || 'ar3cli.sarif'", context, status) == "ar3cli.sarif"
    assert evaluate("!cancelled() && (inputs.sarif != '' || inputs.upload-sarif == 'true')", context, status)
    assert not evaluate("inputs.upload-sarif == 'false' && steps.sarif.outcome == 'success'", context, status)


# -- the steps, executed ------------------------------------------------------------------------------------


def test_broken_file_fails_with_annotations_summary_outputs_and_sarif(robots, tmp_path):
    (robots / "results").mkdir()
    run = run_action(robots, tmp_path, paths="robots", sarif="results/ar3cli.sarif")
    assert run.steps["lint"]["outcome"] == "failure", run.stderr
    assert run.failed
    assert run.outputs["exit-code"] == "1" and run.outputs["failed"] == "true"
    errors = [line for line in run.stdout.splitlines() if line.startswith("::error ")]
    (error,) = errors  # three I001 findings in one file: one annotation with the count
    assert "file=robots/broken.urdf,line=152" in error and "title=I001 (3 in this file)::3x: " in error
    assert "good.urdf" not in run.stdout
    assert "## ar3cli lint-urdf" in run.summary
    assert "| location | rule | severity | message | hint |" in run.summary
    assert "`robots/broken.urdf:152:3` | I001 | error | 3x: " in run.summary and "<details>" in run.summary
    # the SARIF step runs even though the lint step failed
    assert run.steps["sarif"]["outcome"] == "success", run.stderr
    assert run.outputs["sarif-file"] == "results/ar3cli.sarif"
    sarif = json.loads((robots / "results" / "ar3cli.sarif").read_text(encoding="utf-8"))
    assert sarif["version"] == "2.1.0"
    (result,) = sarif["runs"][0]["results"]  # one result per rule and file, the others its related locations
    assert result["ruleId"] == "I001" and len(result["relatedLocations"]) == 2
    assert run.steps["upload-sarif"]["outcome"] == "skipped"


def test_clean_file_passes_without_sarif(robots, tmp_path):
    run = run_action(robots, tmp_path, paths="robots/good.urdf")
    assert not run.failed, run.stderr
    assert run.outputs == {"exit-code": "0", "failed": "false", "sarif-file": ""}
    assert "::error" not in run.stdout and "::warning" not in run.stdout
    assert "## ar3cli lint-urdf" in run.summary
    assert run.steps["sarif"]["outcome"] == "skipped"
    assert not list(robots.glob("*.sarif"))


def test_args_exit_zero_keeps_annotations_but_passes(robots, tmp_path):
    run = run_action(robots, tmp_path, paths="robots", args="--exit-zero")
    assert not run.failed, run.stderr
    assert run.outputs["exit-code"] == "0" and run.outputs["failed"] == "false"
    assert run.stdout.count("::error file=robots/broken.urdf") == 1 and "(3 in this file)" in run.stdout


def test_args_ignore_and_several_paths(robots, tmp_path):
    run = run_action(robots, tmp_path, paths="robots/good.urdf\nrobots/broken.urdf\n", args="--ignore I001 --no-cache")
    assert not run.failed, run.stderr
    assert "::error" not in run.stdout
    assert "2 files checked" in run.stdout


def test_fail_on_warning(robots, tmp_path):
    shutil.copy(ASSETS / "examples" / "ar3_fake_continuous.urdf", robots / "continuous.urdf")
    (tmp_path / "default").mkdir()
    passed = run_action(robots, tmp_path / "default", paths="continuous.urdf")
    assert not passed.failed and "::warning file=continuous.urdf" in passed.stdout
    (tmp_path / "strict").mkdir()
    failed = run_action(robots, tmp_path / "strict", paths="continuous.urdf", **{"fail-on": "warning"})
    assert failed.failed and failed.outputs["exit-code"] == "1" and failed.outputs["failed"] == "true"


def test_upload_sarif_writes_the_default_file_and_would_upload_it(robots, tmp_path):
    run = run_action(robots, tmp_path, paths="robots", **{"upload-sarif": "true"})
    assert run.failed
    assert run.outputs["sarif-file"] == "ar3cli.sarif"
    assert json.loads((robots / "ar3cli.sarif").read_text(encoding="utf-8"))["runs"][0]["results"]
    assert run.steps["upload-sarif"]["outcome"] == "success"
    assert run.would_use["github/codeql-action/upload-sarif"]["sarif_file"] == "ar3cli.sarif"


def test_a_pull_request_from_a_fork_cannot_silence_the_gate(robots, tmp_path):
    """A pyproject.toml with ``ignore = ["ALL"]`` (or ``ar3cli: ignore`` comments) committed in a
    pull request turned a failing file into "passed". From another repository the action lints
    ``--isolated`` (its own branches keep the configuration), and the SARIF run does the same."""
    (robots / "pyproject.toml").write_text('[tool.ar3cli.lint]\nignore = ["ALL"]\n', encoding="utf-8")
    fork = {"repository": "owner/robot", "event": {"pull_request": {"head": {"repo": {"full_name": "someone/robot"}}}}}
    own = {"repository": "owner/robot", "event": {"pull_request": {"head": {"repo": {"full_name": "owner/robot"}}}}}
    (tmp_path / "fork").mkdir()
    isolated = run_action(robots, tmp_path / "fork", github=fork, paths="robots", **{"upload-sarif": "true"})
    assert isolated.failed and isolated.outputs["exit-code"] == "1", isolated.stderr
    assert "--isolated" in isolated.stderr  # the three I001 errors, as one grouped annotation
    assert [line.split("::")[1] for line in isolated.stdout.splitlines() if line.startswith("::error file=")] == [
        "error file=robots/broken.urdf,line=152,col=3,title=I001 (3 in this file)"]
    sarif = json.loads((robots / "ar3cli.sarif").read_text(encoding="utf-8"))
    assert not any("suppressions" in result for result in sarif["runs"][0]["results"])
    (tmp_path / "own").mkdir()
    configured = run_action(robots, tmp_path / "own", github=own, paths="robots")
    assert not configured.failed, configured.stderr
    assert "3 suppressed (3 by pyproject.toml)" in configured.stdout and "3 suppressed" in configured.summary
    (tmp_path / "forced").mkdir()
    forced = run_action(robots, tmp_path / "forced", github=own, paths="robots", isolated="true")
    assert forced.failed


def test_missing_path_is_exit_code_2(robots, tmp_path):
    run = run_action(robots, tmp_path, paths="robots/nothing_here.urdf")
    assert run.failed
    assert run.outputs["exit-code"] == "2" and run.outputs["failed"] == "true"
    assert "no such file or directory" in run.stderr


# -- the workflow documented in docs/ci.md ------------------------------------------------------------------


def _documented_action_steps() -> list[dict]:
    text = (REPO / "docs" / "ci.md").read_text(encoding="utf-8")
    steps = []
    for block in re.findall(r"```yaml\n(.*?)```", text, re.DOTALL):
        document = yaml.safe_load(block)
        for job in (document.get("jobs") or {}).values() if isinstance(document, dict) else []:
            steps += [step for step in job["steps"]
                      if re.fullmatch(r"\./|[\w.-]+/ar3cli@[\w.-]+", step.get("uses", ""))]
    return steps


def test_documented_workflow_uses_the_action_with_declared_inputs():
    steps = _documented_action_steps()
    assert steps, "docs/ci.md has no workflow that uses the action"
    for step in steps:
        assert set(step.get("with", {})) <= set(_action()["inputs"])


def test_documented_workflow_runs(robots, tmp_path):
    (robots / "assets").symlink_to(ASSETS, target_is_directory=True)
    for number, step in enumerate(_documented_action_steps()):
        (tmp_path / str(number)).mkdir()
        inputs = {name: str(value).lower() if isinstance(value, bool) else str(value)
                  for name, value in step.get("with", {}).items()}
        run = run_action(robots, tmp_path / str(number), **inputs)
        assert not run.failed, f"{step}\n{run.stdout[-2000:]}\n{run.stderr[-2000:]}"
        assert run.outputs["exit-code"] == "0"
        assert "## ar3cli lint-urdf" in run.summary


def test_diff_input_posts_the_markdown_diff_of_the_changed_robots(tmp_path):
    import subprocess

    from tests.test_diff import ARM

    workspace = tmp_path / "workspace"
    (workspace / "robots").mkdir(parents=True)
    (workspace / "robots" / "arm.urdf").write_text(ARM, encoding="utf-8")
    (workspace / "robots" / "same.urdf").write_text(ARM, encoding="utf-8")
    git = ["git", "-c", "user.name=t", "-c", "user.email=t@example.com", "-c", "commit.gpgsign=false", "-C", str(workspace)]
    for args in (["init", "-q"], ["add", "-A"], ["commit", "-qm", "arm"]):
        subprocess.run([*git, *args], check=True, capture_output=True)
    (workspace / "robots" / "arm.urdf").write_text(ARM.replace('xyz="0 0 0.3"', 'xyz="0 0 0.34"'), encoding="utf-8")
    run = run_action(workspace, tmp_path, paths="robots", diff="true", **{"diff-base": "HEAD"})
    assert run.steps["diff"]["outcome"] == "success", run.stderr  # changes are reported, not a failure
    assert "## ar3cli diff" in run.summary and "## ar3cli lint-urdf" in run.summary
    assert "robots/arm.urdf" in run.summary and "same.urdf" not in run.summary.split("## ar3cli diff")[1]
    assert "| kinematics | joint 'elbow' | origin |" in run.summary
    (tmp_path / "off").mkdir()
    assert run_action(workspace, tmp_path / "off", paths="robots").steps["diff"]["outcome"] == "skipped"
