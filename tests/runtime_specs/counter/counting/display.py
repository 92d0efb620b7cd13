def show(inputs, outputs, context):
    outputs.shown = inputs.value


def echo(inputs, outputs, context):
    outputs.echo = inputs.shown
