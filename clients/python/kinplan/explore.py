"""The old import path of :mod:`kinplan.exploration_loop` (the values of the
exploration loop and of the reference cells), kept for one release; import
from :mod:`kinplan.exploration_loop`."""
from typing import Any

from .exploration_loop import SCENES, ExploreStep, ExploreSummary, ReferenceScene

__all__ = ["SCENES", "ExploreStep", "ExploreSummary", "ReferenceScene"]


def __getattr__(name: str) -> Any:
    """``ExploreMixin``, a client mixin of earlier releases: the class that now holds its methods."""
    if name == "ExploreMixin":
        from .client import Client

        return Client
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
