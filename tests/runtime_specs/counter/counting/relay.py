def store(inputs, outputs, context):
    outputs.last = inputs.command


def count_lost(inputs, outputs, context):
    outputs.last = inputs.command
    outputs.lost = inputs.lost + 1


def relay(inputs, outputs, context):
    outputs.forward = inputs.last
    outputs.back = inputs.last
