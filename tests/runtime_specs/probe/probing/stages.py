def swap_a(inputs, outputs, context):
    outputs.x = inputs.y + 1


def swap_b(inputs, outputs, context):
    outputs.y = inputs.x


def trip(inputs, outputs, context):
    outputs.trips = inputs.trips + 1
    mode = context.parameters["MODE"]
    if context.iteration != 2:
        return
    if mode == 1:
        raise RuntimeError("the probe trips on purpose")
    if mode == 2:
        outputs.recoveries = 99  # declared by recover/pf, not by trip/pf
    if mode == 3:
        outputs.trips = "many"
    if mode == 4:
        outputs.trips = inputs.recoveries  # read by recover/pf, not by trip/pf
    if mode == 5:
        outputs.trips = [1, 2]  # a list where an int is declared


def recover(inputs, outputs, context):
    outputs.recoveries = inputs.recoveries + 1
