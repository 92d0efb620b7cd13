"""The trace writer's own process: `python -m earl.runtime.trace_process FILE` (see trace.py).

It reads length-prefixed msgpack batches from its standard input, written by
`BackgroundSink` in the run's process (trusted: its parent), and applies them to a
`McapSink`.  Ctrl-C reaches every process of the terminal, and SIGTERM or SIGHUP
every process of the group (`timeout`, a closed terminal): this one runs in a
session of its own, where none of them reaches it, ignores them besides, and
finishes the file when the run says so, or when its input ends because the run
was killed.  A write that fails (a full disk) ends it with exit code 1 and one line on
standard error, which the run reports.
"""

from __future__ import annotations

import logging
import signal
import sys
from typing import BinaryIO

import msgpack  # type: ignore[import-untyped]

from earl.runtime.trace import _LENGTH, McapSink


def _read_exactly(stream: BinaryIO, size: int) -> bytes | None:
    data = stream.read(size)
    return data if len(data) == size else None


def write(path: str, source: BinaryIO) -> None:
    header = _read_exactly(source, _LENGTH.size)
    if header is None:
        # Nothing came: the run was stopped as it was set up (Ctrl-C as this process started), and its
        # process has removed the file it made, or will. Opening it now would make it again, and write an
        # empty trace where `earl run` said it wrote none.
        return
    with open(path, "wb") as output:
        sink = McapSink(output)
        while True:
            data = None if header is None else _read_exactly(source, _LENGTH.unpack(header)[0])
            if data is None:  # the run ended without saying so (killed): keep what came
                break
            channels, numbers, times, values, finish = msgpack.unpackb(data, use_list=False, strict_map_key=False)
            # each channel is registered where it came among the messages (its position)
            pending = iter(channels)
            channel = next(pending, None)
            for position, item in enumerate(zip(numbers, times, values, strict=True)):
                while channel is not None and channel[0] == position:
                    sink.channel(*channel[1:])
                    channel = next(pending, None)
                sink.message(*item)
            while channel is not None:  # registered after the batch's last message
                sink.channel(*channel[1:])
                channel = next(pending, None)
            sink.output.raise_error()  # a write that failed (a full disk) ends the run's trace now
            if finish:
                break
            header = _read_exactly(source, _LENGTH.size)
        sink.finish()


def main(argv: list[str]) -> int:
    for stop in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP):
        signal.signal(stop, signal.SIG_IGN)
    # The SDK logs a line for every message it cannot write; the run reads this process's last
    # line of standard error only at the end, so the first error is reported (above) instead.
    logging.disable(logging.CRITICAL)
    try:
        write(argv[0], sys.stdin.buffer)
    except OSError as error:
        print(error.strerror or str(error), file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
