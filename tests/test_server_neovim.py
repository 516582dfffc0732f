"""One real editor: Neovim, headless, with its built-in LSP client, on a real robot file.

Neovim starts ``ar3cli server`` as docs/editors.md tells users to (``vim.lsp.start_client``, then
``buf_attach_client``: both exist since Neovim 0.5, and Debian's 0.7 is what CI installs), opens
pybullet_data's R2-D2, and must receive the findings ``ar3cli lint-urdf`` prints for the same file
in the same folder. Then it edits the buffer as a user would (the fake limits of a continuous joint
deleted) and must see that finding go. Skipped where nvim is not installed.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys

import pytest

from tests.conftest import REPO, run_cli

pytest.importorskip("pygls", reason="the server extra is not installed (pip install 'ar3cli[server]')")
NVIM = shutil.which("nvim")
pytestmark = pytest.mark.skipif(NVIM is None, reason="Neovim is not installed (apt-get install neovim; .ci/run does)")

SCRIPT = r"""
local function env(name) return os.getenv(name) end
local client_id = vim.lsp.start_client({
  name = "ar3cli",
  cmd = { env("AR3CLI_TEST_PYTHON"), "-m", "ar3cli", "server" },
  root_dir = env("AR3CLI_TEST_ROOT"),
  cmd_env = { PYTHONPATH = env("AR3CLI_TEST_PYTHONPATH") },
})
vim.cmd("edit " .. vim.fn.fnameescape(env("AR3CLI_TEST_FILE")))
local buf = vim.api.nvim_get_current_buf()
vim.lsp.buf_attach_client(buf, client_id)

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
vim.lsp.stop_client(client_id)
vim.cmd("qa!")
"""


def test_neovim_receives_lint_urdfs_findings_and_sees_an_edit_fix_one(tmp_path, pybullet_data_dir):
    robot = pybullet_data_dir / "r2d2.urdf"
    script, out = tmp_path / "client.lua", tmp_path / "out.json"
    script.write_text(SCRIPT)
    env = {**os.environ, "AR3CLI_TEST_PYTHON": sys.executable, "AR3CLI_TEST_ROOT": str(robot.parent),
           "AR3CLI_TEST_PYTHONPATH": str(REPO), "AR3CLI_TEST_FILE": str(robot), "AR3CLI_TEST_OUT": str(out),
           **{name: str(tmp_path / name.lower()) for name in ("XDG_CONFIG_HOME", "XDG_DATA_HOME", "XDG_STATE_HOME",
                                                               "XDG_CACHE_HOME")}}
    done = subprocess.run([NVIM, "--headless", "--clean", "-n", "-c", f"luafile {script}"], env=env, cwd=tmp_path,
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
