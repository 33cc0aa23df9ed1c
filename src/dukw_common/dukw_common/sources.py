"""Single-source rule for safety topics and services. ROS-free.

A command topic (``tracks/cmd``, ``props/cmd``), a state the controller obeys
(``drive_mode``, ``authority``) or a service that changes the vehicle's state
(``set_mode``, ``set_pose``) has exactly one expected source on the vehicle. Without
DDS-Security anyone on the domain can add a second one; the stack cannot tell which
is genuine, so a second source means: refuse (neutral) and report ERROR until it is
gone. Nodes count sources with the ROS graph (node_tools.graph_sources).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Sequence


@dataclass
class SourceWatch:
    """The latest source count per topic or service name; ``fault`` says what is wrong."""

    counts: dict[str, int] = field(default_factory=dict)
    names: dict[str, tuple[str, ...]] = field(default_factory=dict)

    def update(self, name: str, count: int, node_names: Sequence[str] = ()) -> bool:
        """Record ``count`` sources of ``name``; True when the verdict changed."""
        before = self.counts.get(name, 0) > 1
        self.counts[name] = int(count)
        self.names[name] = tuple(node_names)
        return before != (count > 1)

    def fault(self) -> str:
        """'' while every name has at most one source, else which have more."""
        bad = [f'{n} has {c} sources' + (f' ({", ".join(self.names[n])})' if self.names[n]
                                         else '')
               for n, c in sorted(self.counts.items()) if c > 1]
        return '; '.join(bad)
