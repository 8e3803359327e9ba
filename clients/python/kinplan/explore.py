"""The old import path of :mod:`kinplan.exploration_loop` (the values of the
exploration loop and of the reference cells), kept for one release; import
from :mod:`kinplan.exploration_loop`."""
from .exploration_loop import SCENES, ExploreStep, ExploreSummary, ReferenceScene

__all__ = ["SCENES", "ExploreStep", "ExploreSummary", "ReferenceScene"]
