def increment(inputs, outputs, context):
    outputs.count = inputs.count + 1


def send(inputs, outputs, context):
    outputs.count = inputs.count


def rest(inputs, outputs, context):
    outputs.sent = inputs.count
