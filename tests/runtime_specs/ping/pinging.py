def inc(inputs, outputs, context):
    outputs.n = inputs["in"] + 1


def send(inputs, outputs, context):
    outputs.out = inputs.n


def count(inputs, outputs, context):
    outputs.n = inputs.n + 1
