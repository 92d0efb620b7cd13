"""The Python side of `examples/mobile_robot`: the functions its spec binds, and the planar world
its real effectors and receptors act in (`environment.py`)."""
