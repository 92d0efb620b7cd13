def summary(simulation):
    env = simulation.environment
    return f"sorter: binned={dict(sorted(env.binned.items()))} lost={env.lost} on_belt={len(env.parts)}"
