def classify(inputs, outputs, context):
    d = inputs.detection
    outputs.lastPart = d.partId
    outputs.target = d.colour
    outputs.sorted = inputs.sorted + 1
    per_bin = list(inputs.perBin)
    per_bin[d.colour - 1] += 1
    outputs.perBin = per_bin


def command(inputs, outputs, context):
    speed = context.parameters["BELT_SPEED"]
    k = inputs.target
    station = 0.4 + 0.3 * k
    outputs.push[k] = {
        "partId": inputs.lastPart,
        "pushAt": context.time + (station - 0.2) / speed - 0.05,
        "abort": False,
    }
    outputs.beltSpeed = speed


def run(inputs, outputs, context):
    outputs.target = 0


def drive(inputs, outputs, context):
    outputs.beltSpeed = context.parameters["BELT_SPEED"]


def halt(inputs, outputs, context):
    outputs.target = 0


def stop_belt(inputs, outputs, context):
    outputs.beltSpeed = 0.0
