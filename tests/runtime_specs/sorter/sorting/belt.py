def convert(inputs, outputs, context):
    outputs.voltage = 10.0 * inputs.speed


def out(inputs, outputs, context):
    outputs.voltage = inputs.voltage


def apply(inputs, outputs, context):
    outputs.applied = inputs.voltage
    context.environment.speed = inputs.voltage / 10.0
