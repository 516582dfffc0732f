"""benchmarks/mutations.py stays applicable: each mutation's line is in its file exactly once, and the tests
it names exist. A refactor that moved a line (scan's ``storable(absolute)``) left the script exiting 2 with
"update benchmarks/mutations.py", which only a run of the script saw."""

from __future__ import annotations

import importlib.util
import sys

import pytest

from tests.conftest import REPO


def _mutations():
    spec = importlib.util.spec_from_file_location("mutations", REPO / "benchmarks" / "mutations.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # dataclasses resolve the module's annotations through sys.modules
    spec.loader.exec_module(module)
    return module.MUTATIONS


@pytest.mark.parametrize("mutation", _mutations(), ids=lambda mutation: mutation.name)
def test_each_mutation_still_applies_and_names_real_tests(mutation):
    text = (REPO / mutation.file).read_text(encoding="utf-8")
    assert text.count(mutation.old) == 1, f"{mutation.name}: update benchmarks/mutations.py"
    for test in mutation.tests:
        path = test.split("::", 1)[0]
        assert (REPO / path).is_file(), f"{mutation.name} names {test}"
