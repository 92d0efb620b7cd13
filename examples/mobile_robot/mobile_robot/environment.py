"""The environment of `earl run examples/mobile_robot` (named in run.toml): the room, the base and its
lidar (world.py).  `make_environment(system, seed)` reads the base's wheels and geometry from the
spec, places the posts of the room (one moved by up to 5 cm, drawn from the seed) and starts the base
at the origin, facing +x."""

from __future__ import annotations

from typing import Any

import numpy as np

from mobile_robot.world import Obstacle, Room, World

#: the posts of the room: one stands near the second leg of the route, so the base must go around it
OBSTACLES = (Obstacle(2.5, 3.8, 0.25), Obstacle(6.5, 6.5, 0.3), Obstacle(-1.0, 5.5, 0.2))
JITTER = 0.05


def _parameter(owner: Any, name: str) -> Any:
    found = next((p for p in owner.parameters if p.name == name), None)
    if found is None:
        raise ValueError(f"the mobile robot's environment needs the parameter `{name}` of {owner.name}")
    return found.value.value


def make_environment(system: Any, seed: int) -> World:
    """The world for `system` (expanded: the number of wheels is its WHEELS)."""
    base = next((agent for agent in system.agents if agent.name == "base"), None)
    if base is None:
        raise ValueError("the mobile robot's environment needs an agent `base/a`")
    wheels = sum(1 for subsystem in base.subsystems if subsystem.name == "wheelDrive")
    random = np.random.default_rng(seed)
    shift = random.uniform(-JITTER, JITTER, size=2)
    posts = [Obstacle(OBSTACLES[0].x + float(shift[0]), OBSTACLES[0].y + float(shift[1]), OBSTACLES[0].radius)]
    room = Room(obstacles=[*posts, *OBSTACLES[1:]])
    return World(
        room, wheels, float(_parameter(base, "WHEEL_RADIUS")), float(_parameter(base, "TRACK_WIDTH")), (0.0, 0.0, 0.0)
    )


def make_environment_wheel_fault(system: Any, seed: int) -> World:
    """The same world, with the left wheel's driver in fault from 8 s to 9 s of run time: the base stops
    for an emergency, and the coordinator has it resume once the fault is gone."""
    world = make_environment(system, seed)
    world.fault_windows.append((1, 8.0, 9.0))
    return world
