"""One missing mesh does not stop the commands that need no meshes (issue 36, item 3).

The fixture is a real robot: pybullet_data's KUKA iiwa copied without ``meshes/link_3.stl`` (its
collision mesh), as a checkout with one mesh never pulled looks. fk-verify, sample-collisions,
render and info --torques go on without that shape and say so in one warning line; lint-urdf --sim
still reports that pybullet itself cannot load the file (P001), which is true of the file as written.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

from ar3cli.sim.loadable_copy import loadable_document, unloadable_shapes
from ar3cli.urdf.model import load_model


@pytest.fixture(scope="module")
def iiwa_without_link_3(pybullet_data_dir: Path, tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("iiwa") / "kuka_iiwa"
    shutil.copytree(pybullet_data_dir / "kuka_iiwa", folder)
    (folder / "meshes" / "link_3.stl").unlink()
    return folder / "model.urdf"


def test_the_copy_leaves_out_only_the_shape_pybullet_cannot_load(iiwa_without_link_3: Path) -> None:
    from lxml import etree

    model = load_model(iiwa_without_link_3)
    left_out = unloadable_shapes(model)
    assert [(item.link, item.role, item.place.line) for item in left_out] == [("lbr_iiwa_link_3", "collision", 164)]
    assert "link_3.stl: file not found" in left_out[0].reason
    strict = etree.fromstring(loadable_document(model))
    partial = etree.fromstring(loadable_document(model, leave_out_unloadable=True))
    assert len(partial.findall("link/collision")) == len(strict.findall("link/collision")) - 1
    assert len(partial.findall("link/visual")) == len(strict.findall("link/visual"))


def test_fk_verify_goes_on_and_says_what_it_left_out(iiwa_without_link_3: Path, cli) -> None:
    result = cli("fk-verify", str(iiwa_without_link_3), "--samples", "20", "--format", "json")
    assert result.code == 0, result.stderr
    data = json.loads(result.stdout)
    assert data["passed"] and [item["link"] for item in data["left_out"]] == ["lbr_iiwa_link_3"]
    warning = [line for line in result.stderr.splitlines() if "warning" in line]
    assert len(warning) == 1 and "link frames do not depend on meshes" in warning[0]


def test_sample_collisions_keeps_the_link_out_of_the_matrix_and_disables_none_of_its_pairs(
        iiwa_without_link_3: Path, cli) -> None:
    result = cli("sample-collisions", str(iiwa_without_link_3), "--samples", "50", "--format", "json")
    assert result.code == 0, result.stderr
    data = json.loads(result.stdout)
    assert data["unchecked_links"] == ["lbr_iiwa_link_3"] and "lbr_iiwa_link_3" not in data["links"]
    assert all("lbr_iiwa_link_3" not in (pair["link_a"], pair["link_b"]) for pair in data["pairs"])
    categories = {frozenset((pair["link_a"], pair["link_b"])): pair["category"] for pair in data["pairs"]}
    # link_3 keeps its place in the adjacency: link_2 and link_4 are not adjacent through it
    assert categories[frozenset(("lbr_iiwa_link_2", "lbr_iiwa_link_4"))] != "adjacent"
    assert [warning["rule"] for warning in data["warnings"]][:1] == ["collision-left-out"]
    assert "visual-only-links" not in [warning["rule"] for warning in data["warnings"]]


def test_render_draws_the_rest_and_warns_once(iiwa_without_link_3: Path, cli, tmp_path: Path) -> None:
    picture = tmp_path / "iiwa.png"
    result = cli("render", str(iiwa_without_link_3), "-o", str(picture), "--width", "64", "--height", "48",
                 "--format", "json")
    assert result.code == 0, result.stderr
    assert picture.is_file()
    assert [item["link"] for item in json.loads(result.stdout)["collisions_left_out"]] == ["lbr_iiwa_link_3"]
    assert sum("contacts with it are not checked" in line for line in result.stderr.splitlines()) == 1


def test_lint_sim_still_says_pybullet_cannot_load_the_file_as_written(iiwa_without_link_3: Path, cli) -> None:
    """The other commands go on without the mesh; lint does not pretend the file loads: G001 (an error
    because pybullet refuses the file) names the mesh at its line, and P001, which would only restate
    it, stays quiet (one cause, one finding)."""
    result = cli("lint-urdf", "--sim", "--no-cache", "--select", "P001,G001", str(iiwa_without_link_3),
                 "--format", "json")
    assert result.code == 1, result.stderr
    findings = json.loads(result.stdout)["findings"]
    (missing,) = [finding for finding in findings if finding["rule"] == "G001"]
    assert missing["severity"] == "error" and "link_3.stl" in missing["message"]
    assert "P001" not in {finding["rule"] for finding in findings}


def test_a_missing_cdf_geometry_is_left_out_too(pybullet_data_dir: Path, cli) -> None:
    """pybullet_data's toys/concave_box.urdf names a concave_box.cdf that pybullet_data does not ship."""
    result = cli("fk-verify", str(pybullet_data_dir / "toys" / "concave_box.urdf"), "--samples", "2")
    assert result.code == 0, result.stderr
    assert "cdf concave_box.cdf: file not found" in result.stderr
