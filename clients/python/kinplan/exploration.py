"""The old import path of :mod:`kinplan.octree` (OctoMap trees and ranked
next-best views), kept for one release; import from :mod:`kinplan.octree`."""
from .octree import GAINS, Octree, Views

__all__ = ["GAINS", "Octree", "Views"]
