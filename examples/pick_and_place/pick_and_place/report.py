"""The closing line of `earl run examples/pick_and_place` (`report` in run.toml)."""

from __future__ import annotations

from typing import Any


def summary(simulation: Any) -> str:
    """`pick-and-place: placed=<true|false> error_mm=<float> sim_time_s=<float> wall_time_s=<float>`.

    Lines about pictures (written, or why not) come first, so the summary is the last line.
    """
    environment = simulation.environment
    placement = environment.placement()
    lines = [f"picture: {path}" for path in environment.pictures]
    lines += list(environment.render_messages)
    wall = environment.wall_time if environment.wall_time is not None else float("nan")
    lines.append(
        f"pick-and-place: placed={'true' if placement.placed else 'false'} error_mm={placement.error_mm:.2f} "
        f"sim_time_s={simulation.time:.3f} wall_time_s={wall:.3f}"
    )
    return "\n".join(lines)
