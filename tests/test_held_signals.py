"""Stop signals held back while a compiled module initialises (earl/held_signals.py), with real signals."""

from __future__ import annotations

import signal
import threading
from types import FrameType

import pytest

from earl.held_signals import stop_signals_held


def test_a_signal_held_is_handled_once_the_block_is_done_by_the_handler_in_place_before() -> None:
    came: list[int] = []

    def handler(number: int, _frame: FrameType | None) -> None:
        came.append(number)

    before = signal.signal(signal.SIGTERM, handler)
    try:
        with stop_signals_held():
            signal.raise_signal(signal.SIGTERM)
            signal.raise_signal(signal.SIGTERM)
            assert came == []  # held: nothing of the block's is interrupted
        assert came == [signal.SIGTERM, signal.SIGTERM]
        assert signal.getsignal(signal.SIGTERM) is handler
    finally:
        signal.signal(signal.SIGTERM, before)


def test_ctrl_c_held_raises_its_keyboard_interrupt_after_the_block() -> None:
    reached = False
    with pytest.raises(KeyboardInterrupt), stop_signals_held():
        signal.raise_signal(signal.SIGINT)
        reached = True
    assert reached


def test_an_ignored_signal_stays_ignored_and_another_thread_holds_nothing() -> None:
    before = signal.signal(signal.SIGTERM, signal.SIG_IGN)
    try:
        with stop_signals_held():
            assert signal.getsignal(signal.SIGTERM) is signal.SIG_IGN
            signal.raise_signal(signal.SIGTERM)
        assert signal.getsignal(signal.SIGTERM) is signal.SIG_IGN
    finally:
        signal.signal(signal.SIGTERM, before)
    handlers: list[object] = []

    def elsewhere() -> None:
        with stop_signals_held():
            handlers.append(signal.getsignal(signal.SIGINT))

    thread = threading.Thread(target=elsewhere)
    thread.start()
    thread.join()
    assert handlers == [signal.getsignal(signal.SIGINT)]
