"""Links between processes and hosts: the codec, the Zenoh transport, the deployment file.

In-process links stay what the runtime makes them (a channel per input buffer); only a
link whose two ends run in different processes goes through here (docs/distributed.md).
"""
