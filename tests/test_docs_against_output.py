"""The docs say what the code does (issue 36, item 11): counts, inputs and commands checked against
their source, so a doc cannot drift from the output again."""

from __future__ import annotations

import ast
import re
import subprocess

from tests.conftest import REPO


def _block(text: str, marker: str) -> str:
    """The command between README's ``<!-- marker -->`` lines, as ``.ci/run`` reads it."""
    inside = text.split(f"<!-- {marker} -->", 1)[1].split(f"<!-- /{marker} -->", 1)[0]
    return "\n".join(line for line in inside.splitlines() if line and not line.startswith("```"))


def test_the_install_check_count_is_the_number_of_checks() -> None:
    from ar3cli.install_check.capabilities import CAPABILITY_CHECKS
    from ar3cli.install_check.checks import CHECKS

    count = len(CHECKS) + len(CAPABILITY_CHECKS)
    for doc in ("README.md", "docs/getting-started.md", "docs/commands/install-check.md"):
        said = re.findall(r"ready: (\d+) checks", (REPO / doc).read_text())
        assert said and {int(number) for number in said} == {count}, doc
    assert f"{count} checks (it ends with" in (REPO / "README.md").read_text()


def test_the_two_set_up_commands_use_two_venvs_and_ci_reads_the_test_command() -> None:
    readme = (REPO / "README.md").read_text()
    venvs = [re.search(r"python3 -m venv (\S+)", _block(readme, marker)).group(1)
             for marker in ("main-command", "test-command")]
    assert len(set(venvs)) == 2, venvs
    read_by_ci = subprocess.run(
        ["bash", "-c", "sed -n '/<!-- test-command -->/,/<!-- \\/test-command -->/p' README.md "
                       "| grep -v '^<!--' | grep -v '^```'"], cwd=REPO, capture_output=True, text=True, check=True)
    assert read_by_ci.stdout.strip() == _block(readme, "test-command") and "pytest" in read_by_ci.stdout


def test_every_input_of_the_action_is_documented() -> None:
    import yaml

    inputs = yaml.safe_load((REPO / "action.yml").read_text())["inputs"]
    documented = set(re.findall(r"^\| `([a-z-]+)` \|", (REPO / "docs" / "ci.md").read_text(), re.MULTILINE))
    assert set(inputs) <= documented, sorted(set(inputs) - documented)


def test_skip_reasons_are_fixed_text() -> None:
    """A skip reason built from a path printed the machine's folders; every reason is a literal string."""
    built = []
    for path in sorted((REPO / "tests").glob("*.py")):
        for node in ast.walk(ast.parse(path.read_text())):
            if not isinstance(node, ast.Call):
                continue
            name = getattr(node.func, "attr", getattr(node.func, "id", ""))
            reasons = [keyword.value for keyword in node.keywords if keyword.arg == "reason"]
            if name == "skip" and node.args:
                reasons.append(node.args[0])
            built += [f"{path.name}:{node.lineno}" for reason in reasons if isinstance(reason, ast.JoinedStr)]
    assert built == []


def test_lint_urdf_help_fits_in_a_screenful_of_panels(cli) -> None:
    """236 lines at 80 columns, one panel; the shared options have a panel of their own."""
    result = cli("lint-urdf", "--help", env={"COLUMNS": "80"})
    assert result.code == 0
    assert len(result.stdout.splitlines()) < 170
    assert "Robot files, writes and limits" in result.stdout and "Simulation" in result.stdout
