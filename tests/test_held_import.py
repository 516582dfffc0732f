"""A library that swallows interrupts during its import (trimesh: ``except BaseException`` around
its optional imports) must not swallow a Ctrl-C or SIGTERM: :mod:`ar3cli.infra.held_import`."""

from __future__ import annotations

import importlib
import signal
import sys

import pytest

from ar3cli.infra.held_import import import_holding_interrupts

SWALLOWER = '''
import os, signal, time
try:
    os.kill(os.getpid(), signal.SIGINT)
    time.sleep(0.05)  # the handler runs here, if the signal is not held back
    swallowed = False
except BaseException:  # as trimesh's optional imports do
    swallowed = True
'''


@pytest.fixture
def swallower(tmp_path, monkeypatch):
    (tmp_path / "swallows_interrupts.py").write_text(SWALLOWER)
    monkeypatch.syspath_prepend(str(tmp_path))
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    yield "swallows_interrupts"
    signal.signal(signal.SIGINT, previous)
    sys.modules.pop("swallows_interrupts", None)


def test_a_plain_import_loses_the_interrupt(swallower):
    module = importlib.import_module(swallower)
    assert module.swallowed  # the Ctrl-C is gone: the run would go on


def test_a_held_import_delivers_the_interrupt_once_done(swallower):
    with pytest.raises(KeyboardInterrupt):
        import_holding_interrupts(swallower)
    assert sys.modules[swallower].swallowed is False  # nothing raised inside the library's import


def test_an_imported_module_is_returned_as_it_is():
    import json

    assert import_holding_interrupts("json") is json
