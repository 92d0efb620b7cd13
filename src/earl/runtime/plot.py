"""`earl plot`: signals of a trace against time, with the FSM states shaded as bands (Matplotlib)."""

from __future__ import annotations

from pathlib import Path

from earl.runtime.trace_reader import signal, state_bands, summarise


def plot_signals(trace: Path, signals: list[str], output: Path, title: str | None = None) -> None:
    """Write a PNG (or SVG/PDF, by the suffix) with one panel per subsystem of the signals."""
    import matplotlib

    matplotlib.use("Agg")  # files only: no display needed, none opened
    import matplotlib.pyplot as plt

    summary = summarise(trace)
    end = summary.end_time * 1e-9
    series = [(name, *signal(trace, name)) for name in signals]
    subsystems = list(dict.fromkeys(subsystem for _, subsystem, _, _ in series))
    figure, axes = plt.subplots(
        len(subsystems), 1, figsize=(10, 2.8 * len(subsystems) + 0.6), sharex=True, squeeze=False
    )
    palette = plt.get_cmap("Pastel1")
    for row, subsystem in enumerate(subsystems):
        axis = axes[row][0]
        colours: dict[str, object] = {}
        for start, stop, state in state_bands(trace, subsystem, end):
            colour = colours.setdefault(state, palette(len(colours) % 9))
            axis.axvspan(start, stop, color=colour, alpha=0.6, linewidth=0, label=f"state {state}")
        for name, owner, times, values in series:
            if owner == subsystem:
                axis.step(times, values, where="post", label=name[len(subsystem) + 1 :], linewidth=1.2)
        handles, labels = axis.get_legend_handles_labels()
        unique = dict(zip(labels, handles, strict=False))
        axis.legend(unique.values(), unique.keys(), loc="upper right", fontsize=7, ncol=2)
        axis.set_title(subsystem, fontsize=9, loc="left")
        axis.grid(True, alpha=0.3)
    axes[-1][0].set_xlabel("time [s]")
    if title:
        figure.suptitle(title)
    figure.tight_layout()
    output.parent.mkdir(parents=True, exist_ok=True)
    figure.savefig(output, dpi=110)
    plt.close(figure)
