def detect(inputs, outputs, context):
    pixels = inputs.frame.pixels
    centre = pixels[len(pixels) // 2]
    present = centre != 0
    next_id = inputs.nextId
    if present and not inputs.wasPresent:
        next_id += 1
    outputs.nextId = next_id
    outputs.wasPresent = present
    outputs.current = {"present": present, "partId": next_id, "colour": int(centre), "position": 0.2}


def publish(inputs, outputs, context):
    outputs.detection = inputs.current
