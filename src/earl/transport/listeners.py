"""Whether two `listen` endpoints of a deployment would take the same socket of one host.

Only the endpoints of processes on the same host are compared (`same_host` in deployment.py): each
computer has its own ports, so `tcp/0.0.0.0:7451` on one and `tcp/192.168.1.20:7451` on another both listen.

Two processes cannot listen where the operating system gives one socket: the second would fail
as its Zenoh session opens ("Address already in use"). What decides it is the kind of socket the
protocol binds (`tcp`, `tls` and `ws` bind TCP ports; `udp` and `quic` UDP ports), the port, and
the addresses: `tcp/127.0.0.1:7451` and `tcp/[::1]:7451` are two sockets (IPv4 and IPv6 each have
their own port 7451), while `0.0.0.0` binds the port on every IPv4 address and `[::]` on every
address, IPv4 too (Linux's default, `net.ipv6.bindv6only = 0`). `localhost` is 127.0.0.1 or ::1 as
the host resolves it, so it is taken to bind both.
"""

from __future__ import annotations

import ipaddress
from dataclasses import dataclass

#: the socket each network protocol of Zenoh's binds to listen
_SOCKET_KIND = {"tcp": "tcp", "tls": "tcp", "ws": "tcp", "udp": "udp", "quic": "udp"}
#: what the wildcards and `localhost` bind
_EVERY_IPV4, _EVERY_IPV6 = "every IPv4 address", "every IPv6 address"
_BOUND_BY = {
    "0.0.0.0": frozenset({_EVERY_IPV4}),
    "::": frozenset({_EVERY_IPV4, _EVERY_IPV6}),
    "localhost": frozenset({"127.0.0.1", "::1"}),
}
#: why an address binds more than itself, for the message refusing two listeners (the widest first)
_WHY = {
    "::": "`[::]` listens on every address of this host, IPv4 too",
    "0.0.0.0": "`0.0.0.0` listens on every IPv4 address of this host",
    "localhost": "`localhost` is 127.0.0.1 or ::1, as this host resolves it",
}


@dataclass(frozen=True)
class Listener:
    """The socket a `listen` endpoint binds: its kind, its port, and the addresses it takes."""

    kind: str
    port: str
    #: the host as written, normalised (`[::1]` → `::1`, `LOCALHOST` → `localhost`)
    host: str
    addresses: frozenset[str]

    def families(self) -> set[str]:
        """The wildcards whose addresses include one of these (a host name's family is unknown: none)."""
        found = set()
        for address in self.addresses:
            if address in (_EVERY_IPV4, _EVERY_IPV6):
                found.add(address)
                continue
            with_family = _ip(address)
            if with_family is not None:
                found.add(_EVERY_IPV4 if with_family.version == 4 else _EVERY_IPV6)
        return found


def _ip(text: str) -> ipaddress.IPv4Address | ipaddress.IPv6Address | None:
    try:
        address = ipaddress.ip_address(text)
    except ValueError:
        return None
    if isinstance(address, ipaddress.IPv6Address) and address.ipv4_mapped is not None:
        return address.ipv4_mapped  # `[::ffff:127.0.0.1]` is 127.0.0.1 reached over IPv6
    return address


def listener(endpoint: str) -> Listener:
    """The socket `endpoint` (`PROTOCOL/HOST:PORT`, or another protocol's address) binds."""
    protocol, _, address = endpoint.partition("/")
    address = address.split("#", 1)[0].split("?", 1)[0]  # Zenoh's endpoint metadata and configuration
    host, colon, port = address.rpartition(":")
    if protocol not in _SOCKET_KIND or not colon:  # a Unix socket's path, a serial port: the address itself
        return Listener(protocol, "", address, frozenset({address}))
    if port.isascii() and port.isdigit():
        port = str(int(port))  # `07451` is port 7451
    host = host.strip("[]").lower()
    ip = _ip(host)
    if ip is not None:
        host = str(ip)  # `0:0:0:0:0:0:0:1` is ::1
    return Listener(_SOCKET_KIND[protocol], port, host, _BOUND_BY.get(host, frozenset({host})))


def clash(first: Listener, second: Listener) -> str | None:
    """None when both can listen at once; else "" when they are the same endpoint, or why they clash."""
    if (first.kind, first.port) != (second.kind, second.port):
        return None
    if first.host == second.host:
        return ""
    taken = first.addresses & second.addresses
    taken |= first.addresses & second.families()
    taken |= second.addresses & first.families()
    if not taken:
        return None
    hosts = {first.host, second.host}
    return next((why for host, why in _WHY.items() if host in hosts), "")
