def show(inputs, outputs, context):
    outputs.shown = inputs.value
    outputs.noise = float(context.random.normal(0.0, 0.01))


def echo(inputs, outputs, context):
    outputs.echo = inputs.shown
