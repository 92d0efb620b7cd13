def big(inputs, context):
    return inputs.x >= context.parameters["LIMIT"]


def increment(inputs, outputs, context):
    outputs.x = inputs.x + 1
