"""What the structure suite's scripts (check_includes.py, check_calls.py) share: one line per
check ("ok   name", or "FAIL name" and its problems), the closing "N passed, N failed" line and
exit status, and the circles of a directed graph."""
import sys
from collections import deque

_counts = {"passed": 0, "failed": 0}


def check(name, problems):
    if problems:
        _counts["failed"] += 1
        print("FAIL " + name)
        for p in problems[:40]:
            print("     " + p)
        if len(problems) > 40:
            print("     ... %d more" % (len(problems) - 40))
    else:
        _counts["passed"] += 1
        print("ok   " + name)


def finish():
    print("%d passed, %d failed" % (_counts["passed"], _counts["failed"]))
    sys.exit(1 if _counts["failed"] else 0)


def _components(graph):
    """The strongly connected components of {node: [nodes]} (Tarjan's, without recursion)."""
    index, low, on_stack, stack, found = {}, {}, set(), [], []
    nodes = sorted(set(graph) | {m for targets in graph.values() for m in targets})
    for start in nodes:
        if start in index:
            continue
        index[start] = low[start] = len(index)
        stack.append(start)
        on_stack.add(start)
        work = [(start, iter(sorted(graph.get(start, ()))))]
        while work:
            node, successors = work[-1]
            for m in successors:
                if m not in index:
                    index[m] = low[m] = len(index)
                    stack.append(m)
                    on_stack.add(m)
                    work.append((m, iter(sorted(graph.get(m, ())))))
                    break
                if m in on_stack:
                    low[node] = min(low[node], index[m])
            else:
                work.pop()
                if work:
                    parent = work[-1][0]
                    low[parent] = min(low[parent], low[node])
                if low[node] == index[node]:
                    component = []
                    while True:
                        m = stack.pop()
                        on_stack.discard(m)
                        component.append(m)
                        if m == node:
                            break
                    found.append(sorted(component))
    return found


def circles(graph):
    """The circles of {node: [nodes]}: for every edge that lies on one, the shortest circle
    through it, as [a, b, ..., a] starting at its least node; each circle once, sorted. Empty
    when the graph is acyclic."""
    found = set()
    for component in _components(graph):
        members = set(component)
        for a in component:
            for b in sorted(set(graph.get(a, ())) & members):
                # the shortest way back from b to a, inside the component
                before, queue = {b: None}, deque([b])
                while a not in before:
                    n = queue.popleft()
                    for m in sorted(graph.get(n, ())):
                        if m in members and m not in before:
                            before[m] = n
                            queue.append(m)
                path = [a]
                while path[-1] != b:
                    path.append(before[path[-1]])
                ring = [a] + path[::-1][:-1] if a != b else [a]   # a -> b -> ... (a excluded at the end)
                k = ring.index(min(ring))
                found.add(tuple(ring[k:] + ring[:k]))
    return [list(c) + [c[0]] for c in sorted(found)]
