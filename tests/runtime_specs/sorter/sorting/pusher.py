def _status(arm):
    return {"extended": arm.extended, "retracted": arm.retracted, "fault": arm.fault}


def accept(inputs, outputs, context):
    outputs.pending = inputs.command.partId
    outputs.pushAt = inputs.command.pushAt if inputs.command.pushAt is not None else context.time
    outputs.extend = False
    outputs.status = _status(inputs.armState)


def wait(inputs, outputs, context):
    # the time to push was in the command; kept in a module dict for brevity
    outputs.extend = context.time >= inputs.pushAt
    outputs.status = _status(inputs.armState)


def extend(inputs, outputs, context):
    outputs.extend = True
    outputs.status = _status(inputs.armState)


def retract(inputs, outputs, context):
    outputs.extend = False
    outputs.pending = -1
    outputs.status = _status(inputs.armState)


def report(inputs, outputs, context):
    outputs.armCommand = inputs.extend
    outputs.status = inputs.status
