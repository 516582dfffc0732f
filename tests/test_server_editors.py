"""Real editors: Neovim (headless, its built-in LSP client) and Emacs (batch, eglot) on a real robot file.

Neovim runs the configuration docs/editors.md gives users, copied from it (``vim.lsp.start_client``,
then ``buf_attach_client``: both exist since Neovim 0.5, and Debian's 0.7 is what CI installs), opens
pybullet_data's R2-D2, and must receive the findings ``ar3cli lint-urdf`` prints for the same file
in the same folder. Then it edits the buffer as a user would (the fake limits of a continuous joint
deleted) and must see that finding go. Emacs runs docs/editors.md's eglot configuration on the same
file and must show the same findings. Each test is skipped where its editor is not installed (CI
installs Neovim; Emacs with eglot is tried where a developer has it).
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from tests.conftest import REPO, run_cli

pytest.importorskip("pygls", reason="the server extra is not installed (pip install 'ar3cli[server]')")
NVIM = shutil.which("nvim")
EMACS = shutil.which("emacs")
DEBIAN_ELPA = "/usr/share/emacs/site-lisp/elpa/"
"""Where Debian's elpa-* packages (elpa-eglot for Emacs 28) live; ``emacs -Q`` does not load them."""

SCRIPT = r"""
local function env(name) return os.getenv(name) end
vim.cmd("luafile " .. vim.fn.fnameescape(env("AR3CLI_TEST_CONFIG")))  -- docs/editors.md's snippet, as a user has it
vim.cmd("edit " .. vim.fn.fnameescape(env("AR3CLI_TEST_FILE")))
local buf = vim.api.nvim_get_current_buf()

local function found()
  local items = {}
  for _, d in ipairs(vim.diagnostic.get(buf)) do
    local code = d.code or (d.user_data and d.user_data.lsp and d.user_data.lsp.code)
    table.insert(items, { code = code, lnum = d.lnum, col = d.col, end_col = d.end_col, severity = d.severity })
  end
  return items
end

local function has(code)
  for _, item in ipairs(found()) do if item.code == code then return item end end
  return nil
end

local opened = vim.wait(60000, function() return #vim.diagnostic.get(buf) > 0 end, 50)
local first = found()
local edited = false
local j006 = has("J006")
if j006 then  -- the user deletes the fake limits of the continuous joint
  local line = vim.api.nvim_buf_get_lines(buf, j006.lnum, j006.lnum + 1, false)[1]
  line = line:gsub('%s*lower="[^"]*"', ''):gsub('%s*upper="[^"]*"', '')
  vim.api.nvim_buf_set_lines(buf, j006.lnum, j006.lnum + 1, false, { line })
  edited = vim.wait(60000, function() return has("J006") == nil and #vim.diagnostic.get(buf) > 0 end, 50)
end
local handle = io.open(env("AR3CLI_TEST_OUT"), "w")
handle:write(vim.fn.json_encode({ opened = opened, first = first, edited = edited, after = found() }))
handle:close()
for _, client in pairs(vim.lsp.get_active_clients()) do client.stop() end
vim.cmd("qa!")
"""

def documented_snippet(marker: str, language: str) -> str:
    """The code block that follows ``<!-- MARKER -->`` in docs/editors.md: what users copy."""
    text = (REPO / "docs" / "editors.md").read_text(encoding="utf-8")
    after = text.split(f"<!-- {marker} -->\n", 1)[1]
    return after.split(f"```{language}\n", 1)[1].split("```", 1)[0]


def editor_environment(folder: Path) -> dict[str, str]:
    """An editor's environment: ``ar3cli`` on the PATH runs this checkout, its state files in ``folder``."""
    bin_folder = folder / "bin"
    bin_folder.mkdir()
    wrapper = bin_folder / "ar3cli"
    wrapper.write_text(f'#!/bin/sh\nexec "{sys.executable}" -m ar3cli "$@"\n')
    wrapper.chmod(0o755)
    return {**os.environ, "PATH": f"{bin_folder}{os.pathsep}{os.environ.get('PATH', '')}", "PYTHONPATH": str(REPO),
            "HOME": str(folder), **{name: str(folder / name.lower()) for name in (
                "XDG_CONFIG_HOME", "XDG_DATA_HOME", "XDG_STATE_HOME", "XDG_CACHE_HOME")}}


@pytest.mark.skipif(NVIM is None, reason="Neovim is not installed (apt-get install neovim; .ci/run does)")
def test_neovim_receives_lint_urdfs_findings_and_sees_an_edit_fix_one(tmp_path, pybullet_data_dir):
    robot = pybullet_data_dir / "r2d2.urdf"
    script, config, out = tmp_path / "client.lua", tmp_path / "init.lua", tmp_path / "out.json"
    script.write_text(SCRIPT)
    config.write_text(documented_snippet("neovim-config", "lua"))
    env = {**editor_environment(tmp_path), "AR3CLI_TEST_CONFIG": str(config), "AR3CLI_TEST_FILE": str(robot),
           "AR3CLI_TEST_OUT": str(out)}
    done = subprocess.run([NVIM, "--headless", "--clean", "-n", "-c", f"luafile {script}"], env=env, cwd=robot.parent,
                          capture_output=True, text=True, timeout=180, stdin=subprocess.DEVNULL)
    assert out.is_file(), f"nvim wrote nothing (exit {done.returncode}): {done.stdout[-2000:]} {done.stderr[-2000:]}"
    result = json.loads(out.read_text())
    assert result["opened"], "no diagnostics reached Neovim"
    cli = json.loads(run_cli("lint-urdf", str(robot), "--format", "json", "--no-cache", cwd=robot.parent).stdout)
    severity = {"error": 1, "warning": 2, "info": 3}
    expected = sorted((f["rule"], f["line"] - 1, severity[f["severity"]]) for f in cli["findings"])
    assert sorted((item["code"], item["lnum"], item["severity"]) for item in result["first"]) == expected
    assert "J006" in {rule for rule, _, _ in expected}
    assert result["edited"], "deleting the continuous joint's limits in Neovim did not clear J006"
    assert len(result["after"]) == len(result["first"]) - 1


EMACS_SCRIPT = r"""
(let ((default-directory (getenv "AR3CLI_TEST_ELPA")))
  (when (file-directory-p default-directory) (normal-top-level-add-subdirs-to-load-path)))
(require 'eglot)
(require 'json)
(load (getenv "AR3CLI_TEST_CONFIG"))  ; docs/editors.md's snippet, as a user has it
(find-file (getenv "AR3CLI_TEST_FILE"))
(run-hooks 'post-command-hook)  ; eglot-ensure connects after the command that opened the file
(let ((tries 0))
  (while (and (< tries 600) (null (flymake-diagnostics)))
    (accept-process-output nil 0.1)
    (when (= (% tries 10) 0) (flymake-start))
    (setq tries (1+ tries))))
(let ((shown (mapcar (lambda (d) (vector (line-number-at-pos (flymake-diagnostic-beg d)) (flymake-diagnostic-text d)))
                     (flymake-diagnostics))))
  (with-temp-file (getenv "AR3CLI_TEST_OUT") (insert (json-encode (apply #'vector shown)))))
(kill-emacs 0)
"""


def _eglot_loads() -> bool:
    if EMACS is None:
        return False
    probe = f'(progn (let ((default-directory "{DEBIAN_ELPA}")) (when (file-directory-p default-directory) ' \
            '(normal-top-level-add-subdirs-to-load-path))) (require (quote eglot)))'
    return subprocess.run([EMACS, "--batch", "-Q", "--eval", probe], capture_output=True, timeout=60).returncode == 0


@pytest.mark.skipif(not _eglot_loads(), reason="Emacs with eglot is not installed")
def test_emacs_eglot_shows_lint_urdfs_findings(tmp_path, pybullet_data_dir):
    robot = pybullet_data_dir / "r2d2.urdf"
    script, config, out = tmp_path / "client.el", tmp_path / "init.el", tmp_path / "out.json"
    script.write_text(EMACS_SCRIPT)
    config.write_text(documented_snippet("emacs-config", "elisp"))
    env = {**editor_environment(tmp_path), "AR3CLI_TEST_CONFIG": str(config), "AR3CLI_TEST_FILE": str(robot),
           "AR3CLI_TEST_OUT": str(out), "AR3CLI_TEST_ELPA": DEBIAN_ELPA}
    done = subprocess.run([EMACS, "--batch", "-Q", "-l", str(script)], env=env, cwd=robot.parent,
                          capture_output=True, text=True, timeout=180, stdin=subprocess.DEVNULL)
    assert out.is_file(), f"emacs wrote nothing (exit {done.returncode}): {done.stderr[-2000:]}"
    shown = sorted((line, text.split("[", 1)[1].split("]", 1)[0]) for line, text in json.loads(out.read_text()))
    cli = json.loads(run_cli("lint-urdf", str(robot), "--format", "json", "--no-cache", cwd=robot.parent).stdout)
    assert shown == sorted((finding["line"], finding["rule"]) for finding in cli["findings"])
