def grab(inputs, outputs, context):
    outputs.frame = {"pixels": context.environment.frame(), "stamp": context.time}


def send(inputs, outputs, context):
    outputs.frame = inputs.frame
