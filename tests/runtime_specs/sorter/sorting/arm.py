def track(inputs, outputs, context):
    target = 1.0 if inputs.command else 0.0
    pos = inputs.position
    outputs.target = target
    outputs.status = {"extended": pos > 0.95, "retracted": pos < 0.05, "fault": False}


def send(inputs, outputs, context):
    outputs.target = inputs.target
    outputs.status = inputs.status


def move(inputs, outputs, context):
    env = context.environment
    k = context.parameters["K"]
    pos = env.arm.get(k, 0.0)
    step = 10.0 * context.period
    pos = min(pos + step, inputs.target) if inputs.target > pos else max(pos - step, inputs.target)
    env.arm[k] = pos
    outputs.position = pos


def measure(inputs, outputs, context):
    outputs.position = inputs.position
