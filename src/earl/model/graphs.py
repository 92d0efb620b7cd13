"""Cycles in a directed graph of names: types that contain themselves, predicates defined through
themselves.  One walk over every node, without recursion (a chain thousands long is a spec to refuse,
not a stack to overflow), in time linear in the nodes and edges."""

from __future__ import annotations

from collections.abc import Callable, Iterable, Iterator


def cycles(nodes: Iterable[str], successors: Callable[[str], Iterable[str]]) -> Iterator[list[str]]:
    """Each cycle the walk meets, as the path from the node it returns to (`[a, b]` for a -> b -> a).

    The walk starts from `nodes` in their order and follows only successors among them, so a cycle
    begins at the first of its nodes it reaches. Every node on a cycle lies on some cycle yielded, but
    not every cycle through a node is yielded (a -> b -> a and a -> c -> a: both are, each once met)."""
    order = list(dict.fromkeys(nodes))
    known = set(order)
    finished: set[str] = set()
    for root in order:
        if root in finished:
            continue
        path = [root]  # the nodes being walked, each leading to the next
        on_path = {root}
        pending = [iter(successors(root))]
        while pending:
            child = next(pending[-1], None)
            if child is None:
                pending.pop()
                finished.add(path[-1])
                on_path.discard(path.pop())
            elif child in on_path:
                yield path[path.index(child) :]
            elif child not in finished and child in known:
                path.append(child)
                on_path.add(child)
                pending.append(iter(successors(child)))
