def count(inputs, outputs, context):
    outputs.next = inputs.next + 1


def send(inputs, outputs, context):
    outputs.sent = inputs.next


def take(inputs, outputs, context):
    outputs.seen = (*inputs.seen, inputs.received)


def forward(inputs, outputs, context):
    outputs.forward = len(inputs.seen)


def keep(inputs, outputs, context):
    outputs.last = inputs.value
