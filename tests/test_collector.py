"""The collector is paused while a model is built; the `earl` program also freezes what was built."""

from __future__ import annotations

import gc
from collections.abc import Iterator

import pytest

from earl import collector


@pytest.fixture
def unfrozen() -> Iterator[None]:
    gc.unfreeze()
    was = collector.FREEZE_ON_RESUME
    yield
    collector.FREEZE_ON_RESUME = was
    gc.unfreeze()


def test_a_paused_block_restores_the_collector_and_freezes_nothing_by_default(unfrozen: None) -> None:
    assert gc.isenabled()
    with collector.paused():
        assert not gc.isenabled()
        built = [[index] for index in range(1000)]
    assert gc.isenabled() and gc.get_freeze_count() == 0
    gc.disable()
    try:
        with collector.paused():
            pass
        assert not gc.isenabled()  # a collector that was off stays off
    finally:
        gc.enable()
    assert len(built) == 1000


def test_the_program_s_setting_freezes_what_the_block_built(unfrozen: None) -> None:
    collector.FREEZE_ON_RESUME = True
    with collector.paused():
        built = [[index] for index in range(1000)]
    assert gc.isenabled()
    assert gc.get_freeze_count() >= len(built)  # never visited by the collector again
    young = {id(value) for value in gc.get_objects(generation=0)}
    assert not any(id(item) in young for item in built)
