"""`earl plot`: signals of a trace against time, with the FSM states shaded as bands (Matplotlib)."""

from __future__ import annotations

import re
import warnings
from pathlib import Path
from typing import TYPE_CHECKING

from earl.diagnostics import did_you_mean
from earl.model.elements import Memory, OutputBuffer, Subsystem, System
from earl.model.expressions import Literal
from earl.model.text import subsystem_name
from earl.model.types import ArrayType, PrimitiveType, StructType
from earl.runtime.trace_reader import CUT, Signals, read_signals, signal_element, within

if TYPE_CHECKING:
    from matplotlib.figure import Figure

#: the kinds of file a plot is written as, by the suffix (what Matplotlib's Agg backend writes)
PLOT_SUFFIXES = (".png", ".svg", ".pdf", ".jpg", ".jpeg", ".eps", ".ps")


def plot_output_problem(output: Path) -> str | None:
    """Why a plot cannot be written to `output`, known before anything is read or run; None when it can."""
    if not output.name or output.is_dir():
        return "it is a directory; name the picture, e.g. plot.png"
    if output.suffix.lower() not in PLOT_SUFFIXES:
        return f"a plot is written as {', '.join(PLOT_SUFFIXES)}, named by its suffix"
    if output.exists() and not output.is_file():
        return "it is not a regular file (a device, a pipe or a socket)"
    if output.parent.is_dir():
        return None
    for parent in output.parents:
        if parent.exists() and not parent.is_dir():
            return f"{parent} is a file, not a directory"
    # not made for the plot: a misspelt directory would otherwise get the plot (and the trace beside it)
    return f"the directory `{output.parent}` does not exist"


def what_to_record(expanded: System, signals: list[str]) -> tuple[list[str], list[str]]:
    """What a run that plots `signals` must record: the subsystems whose memory they name, and the
    output buffers (`manip/a.cs.manipulatorState`) whose links carry the values they name
    (`Simulation(record_outputs=…)`). A `ValueError` saying why for a signal that names no memory or
    output buffer of the system, found before the run rather than after it (`earl run --plot`)."""
    subsystems = {subsystem_name(a, s): s for a in expanded.agents for s in a.subsystems}
    longest_first = sorted(subsystems, key=len, reverse=True)
    record: list[str] = []
    sending: list[str] = []
    for signal in signals:
        owner = next((name for name in longest_first if signal.startswith(name + ".")), None)
        if owner is None and signal in subsystems:
            # the subsystem alone: what did-you-mean would suggest is the signal itself
            # memory first: an output buffer is often a struct, itself no signal
            named = [
                *sorted({m.name for m in subsystems[signal].memories}),
                *sorted({o.name for o in subsystems[signal].output_buffers}),
            ]
            listed = ", ".join(f"`{name}`" for name in dict.fromkeys(named))
            example = f", e.g. `{signal}.{named[0]}` (it has {listed})" if named else ""
            raise ValueError(f"`{signal}` names a subsystem: a signal goes on to its memory or output buffer{example}")
        if owner is None:
            family = re.match(r"(.+?)\[(\*|[A-Za-z_]\w*)\](/[a-z]+)\.(.+)", signal)
            if family is not None:
                # `eye[*]/rr.blocked`: a subsystem family is plotted member by member
                head, kind, rest = family.group(1), family.group(3), family.group(4)
                members = [n for n in subsystems if re.fullmatch(re.escape(head) + r"\[\d+\]" + re.escape(kind), n)]
                if members:
                    listed = ", ".join(f"`{member}.{rest}`" for member in members[:4])
                    raise ValueError(
                        f"`{signal}`: a signal names one subsystem; name each member of the family: {listed}"
                        + (" …" if len(members) > 4 else "")
                    )
            prefix = signal.rsplit(".", 1)[0]
            suggestion = did_you_mean(prefix, list(subsystems)) or f"a subsystem such as `{next(iter(subsystems), '')}`"
            raise ValueError(f"`{signal}` does not start with a subsystem of this system; {suggestion}")
        subsystem = subsystems[owner]
        element = signal_element(signal[len(owner) + 1 :])
        memories = sorted({m.name for m in subsystem.memories})
        outputs = sorted({o.name for o in subsystem.output_buffers})
        if element in memories:
            record.append(owner)
        elif element in outputs:  # an output buffer's values are the messages on its links
            indices = sorted({o.index for o in subsystem.output_buffers if o.name == element and o.index is not None})
            if not indices:
                sending.append(f"{owner}.{element}")
            else:  # a family of output buffers: the member the signal names (`out[1]`), or every one (`out[*]`)
                rest = signal[len(owner) + 1 + len(element) :]
                chosen = re.match(r"\[([0-9]+)\]", rest)  # ASCII: `\d` takes `٢` too, which `int` reads as 2
                if chosen is None and not rest.startswith("[*]"):
                    raise ValueError(
                        f"`{signal}`: `{element}` is a family of output buffers; name a member, "
                        f"`{owner}.{element}[{indices[0]}]`, or every one, `{owner}.{element}[*]`"
                    )
                picked = [int(chosen.group(1))] if chosen is not None else indices
                sending += [f"{owner}.{element}[{index}]" for index in picked if index in indices]
        else:
            hint = did_you_mean(element, [*memories, *outputs])
            known = ", ".join(f"`{name}`" for name in dict.fromkeys([*memories, *outputs])) or "none"
            raise ValueError(
                f"`{signal}`: `{owner}` has no memory or output buffer `{element}`"
                + (f"; {hint}" if hint else f" (it has {known})")
            )
        problem = _path_problem(expanded, subsystem, element, signal[len(owner) + 1 + len(element) :])
        if problem is not None:
            raise ValueError(f"`{signal}`: {problem}")
    return sorted(set(record)), sorted(set(sending))


#: `[2]`, `[*]` or `.name` (ASCII digits: `\d` takes `٢` too, which `int` reads as 2)
_STEP = re.compile(r"\[(\*|[0-9]+)\]|\.([A-Za-z_]\w*)")


def _path_problem(expanded: System, subsystem: Subsystem, element: str, path: str) -> str | None:
    """What is wrong with the part of a signal after its element (`[2].motorPos`), or None: an index a
    family or a fixed array does not have, a field its struct does not have."""
    from earl.runtime.values import TypeSystem, ValueTypeError

    declared: list[Memory | OutputBuffer] = [m for m in subsystem.memories if m.name == element]
    declared = declared or [o for o in subsystem.output_buffers if o.name == element]
    steps = [(match.group(1), match.group(2)) for match in _STEP.finditer(path)]
    if "".join(match.group(0) for match in _STEP.finditer(path)) != path:
        return f"`{path}` is not a path of `[index]` and `.field` steps"
    # what the signal names so far (`ball.spin`), so that a problem names the part that has it
    named = element
    members = [d.index for d in declared if d.index is not None]
    if members and steps:  # the first brackets choose a member of the family
        index, _ = steps.pop(0)
        if index is None or (index != "*" and int(index) not in members):
            return f"`{element}` has members {min(members)}..{max(members)}"
        named += f"[{index}]"
    elif members:
        return (
            f"`{element}` is a family of memories, not a number; name a member, `{element}[{min(members)}]`, "
            f"or every one, `{element}[*]`"
        )
    types = TypeSystem(expanded)
    try:
        current: object = types.resolve(declared[0].data_type)
        for index, field in steps:
            if field is not None:
                if not isinstance(current, StructType) or current.field_named(field) is None:
                    hint = (
                        did_you_mean(field, [f.name for f in current.fields])
                        if isinstance(current, StructType)
                        else None
                    )
                    return f"`{named}` has no field `{field}` where the signal names it" + (f"; {hint}" if hint else "")
                current = types.resolve(current.field_named(field).data_type)  # type: ignore[union-attr]
                named += f".{field}"
            else:
                if not isinstance(current, ArrayType):
                    return f"`{named}` is not an array where the signal indexes it"
                size = current.size.value if isinstance(current.size, Literal) else None
                if index != "*" and isinstance(size, int) and int(index) >= size:
                    return f"`{named}` has elements 0 to {size - 1} where the signal indexes it, not {index}"
                current = types.resolve(current.element)
                named += f"[{index}]"
    except ValueTypeError:
        return None  # a type the checker reports; the plot says what it finds
    return _not_a_number(named, current)


def _not_a_number(named: str, resolved: object) -> str | None:
    """Why what a signal names cannot be drawn, or None: a plot draws numbers and Booleans."""
    if isinstance(resolved, StructType):
        fields = ", ".join(f"`{named}.{f.name}`" for f in resolved.fields[:4]) + (
            " …" if len(resolved.fields) > 4 else ""
        )
        return f"`{named}` is a struct ({resolved.name}), not a number; name a field of it: {fields}"
    if isinstance(resolved, ArrayType):
        return f"`{named}` is an array, not a number; name an element, `{named}[0]`, or every one, `{named}[*]`"
    if isinstance(resolved, PrimitiveType) and resolved.name in ("string", "bytes"):
        return f"`{named}` is a {resolved.name}, not a number; a plot draws numbers and Booleans"
    return None


#: the width of the panels' plotting area, in inches; the legends go to the right of it
PANEL_WIDTH = 10.0
#: the height of a panel, in inches
PANEL_HEIGHT = 2.6
#: the legends' font size, in points
LEGEND_FONT = 7
#: the line styles a panel goes through once the ten colours have each been used
LINE_STYLES = ("-", "--", ":", "-.")


def plot_signals(
    trace: Path,
    signals: list[str],
    output: Path,
    title: str | None = None,
    start: float | None = None,
    stop: float | None = None,
) -> list[str]:
    """Write a PNG (or SVG/PDF, by the suffix): one panel per element of a subsystem, its FSM states behind.

    Each panel's legend is to the right of it, outside the axes, so that it hides no data: the figure
    is as much wider as the widest legend needs.

    `start` and `stop` (seconds; None: the run's start or end) draw a window of the run (`within`; a
    ValueError when it is empty).

    Returns a line for each signal left out because it had no value in the run, or the window
    (`Signals.empty`)."""
    import matplotlib

    matplotlib.use("Agg")  # files only: no display needed, none opened
    import matplotlib.pyplot as plt

    data = within(read_signals(trace, signals), start, stop)
    # Matplotlib warns of what it draws (an axis of no width, a layout it cannot fit) at the line of this
    # module that called it: the user would see a Python warning with earl's source path, and can do
    # nothing with it; what earl knows to be wrong it says itself (`within`, `Signals.empty`)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        figure = draw_signals(data, title)
        figure.savefig(output, dpi=110)
    plt.close(figure)
    return [f"{line}; drawn without it" for line in data.empty] + ([CUT] if data.cut else [])


def draw_signals(data: Signals, title: str | None = None) -> Figure:
    """The figure of `plot_signals`, not yet written (Matplotlib's Agg backend chosen by the caller)."""
    import matplotlib.pyplot as plt

    panels = list(dict.fromkeys((s.subsystem, signal_element(s.name)) for s in data.series))
    height = PANEL_HEIGHT * len(panels) + 0.6
    figure, axes = plt.subplots(len(panels), 1, figsize=(PANEL_WIDTH, height), sharex=True, squeeze=False)
    palette = plt.get_cmap("Pastel1")
    legends = []
    for row, (subsystem, element) in enumerate(panels):
        axis = axes[row][0]
        colours: dict[str, object] = {}
        bands = []
        for start, stop, state in data.bands.get(subsystem, []):
            colour = colours.setdefault(state, palette(len(colours) % 9))
            bands.append(axis.axvspan(start, stop, color=colour, alpha=0.6, linewidth=0, label=f"state {state}"))
        lines = []
        drawn = [s for s in data.series if s.subsystem == subsystem and signal_element(s.name) == element]
        for number, series in enumerate(drawn):
            # a value holds until the next one: extend the last to the end of the run
            times = [*series.times, data.end]
            values = [*series.values, series.values[-1]]
            sparse = len(series.times) < 50
            (line,) = axis.step(
                times,
                values,
                where="post",
                label=series.name,
                linewidth=1.2,
                # past the ten colours of the cycle, the line style tells the series apart
                linestyle=LINE_STYLES[number // 10 % len(LINE_STYLES)],
                marker="o" if sparse else None,
                markersize=3,
                # a mark for each message: not the value held when a window starts
                markevery=list(range(int(series.held), len(series.times))) if sparse else None,
            )
            lines.append(line)
        # the signals first, then the states (one entry each, however many stays)
        entries = {line.get_label(): line for line in lines}
        for band in bands:
            entries.setdefault(str(band.get_label()), band)
        # as many rows as the panel's height holds, the rest in more columns
        rows = max(1, int((PANEL_HEIGHT - 0.7) * 72 / (LEGEND_FONT * 1.55)))
        legend = axis.legend(
            list(entries.values()),
            list(entries.keys()),
            loc="upper left",
            bbox_to_anchor=(1.01, 1.0),
            borderaxespad=0.0,
            fontsize=LEGEND_FONT,
            ncol=-(-len(entries) // rows),
        )
        legend.set_in_layout(False)  # placed by the widening below, not by squeezing the panels
        legends.append(legend)
        axis.set_title(f"{subsystem} {element}", fontsize=9, loc="left")
        # no unit: a trace does not carry any
        axis.set_ylabel(_wrapped(panel_label([series.name for series in drawn])), fontsize=8)
        if all(series.boolean for series in drawn):
            axis.set_yticks([0.0, 1.0], ["false", "true"])
            axis.set_ylim(-0.25, 1.25)
        axis.grid(True, alpha=0.3)
        if data.windowed:  # the window's ends, not the first and last sample in it
            axis.set_xlim(data.start, data.end)
    axes[-1][0].set_xlabel("time [s]")
    if title:
        figure.suptitle(title)
    figure.tight_layout()
    # widen the figure by the widest legend, the panels keeping their width
    renderer = figure.canvas.get_renderer()  # type: ignore[attr-defined]
    widest = max(legend.get_window_extent(renderer).width for legend in legends) / figure.dpi
    gap = 0.01 * axes[0][0].get_position().width * PANEL_WIDTH
    width = PANEL_WIDTH + widest + gap + 0.15
    figure.set_size_inches(width, height)
    figure.tight_layout(rect=(0.0, 0.0, PANEL_WIDTH / width, 1.0))
    return figure


def panel_label(names: list[str]) -> str:
    """What a panel's signals are, for its y axis: the name of one (`currentFingerPos`); for several,
    the name they share with `[*]` where their indices differ (`windingCurrent[*]`,
    `manipulatorCommand.jointPosSetpoint[*]`), else the part they start with (`manipulatorCommand`)."""
    paths = [re.findall(r"\[[^\]]*\]|\.?[^.\[]+", name) for name in names]
    first = paths[0]
    if all(len(path) == len(first) for path in paths):
        merged = []
        for steps in zip(*paths, strict=True):
            if len(set(steps)) == 1:
                merged.append(steps[0])
            elif all(step.startswith("[") for step in steps):
                merged.append("[*]")
            else:
                break
        else:
            return "".join(merged)
    shared: list[str] = []
    for steps in zip(*paths, strict=False):
        if len(set(steps)) > 1:
            break
        shared.append(steps[0])
    return "".join(shared)


def _wrapped(label: str, width: int = 30) -> str:
    """A long label on lines of about `width` characters, broken before a `.` (a y axis is short)."""
    lines = [""]
    for part in re.findall(r"\.?[^.]+", label):
        if lines[-1] and len(lines[-1]) + len(part) > width:
            lines.append("")
        lines[-1] += part
    return "\n".join(lines)
