"""The old import path of :mod:`kinplan.octree` (OctoMap trees and ranked
next-best views), kept for one release; import from :mod:`kinplan.octree`."""
from typing import Any

from .octree import GAINS, Octree, Views

__all__ = ["GAINS", "Octree", "Views"]


def __getattr__(name: str) -> Any:
    """``ExplorationMixin``, a client mixin of earlier releases: the class that now holds its methods."""
    if name == "ExplorationMixin":
        from .client import Client

        return Client
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
