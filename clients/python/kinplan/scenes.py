"""kinplan's seeded reference cells for exploration (S0 Fig. 5.2 and 5.8 in
spirit), fetched from the server so that Python and Rust use one definition:

    scene = kinplan.scenes.s0_open_cell(client)
    for step in client.explore(scene=scene, planner="ccstomp"): ...
"""
from __future__ import annotations

from typing import Any

from .exploration_loop import ReferenceScene


def s0_open_cell(client: Any, seed: int = 1) -> ReferenceScene:
    """Two tables with boxes on and under them, a cabinet and a drum in front
    of the IRB 4600; a small part of the region stays hidden after the initial
    scans."""
    scene: ReferenceScene = client.reference_scene("s0_open_cell", seed=seed)
    return scene


def s0_walled_cell(client: Any, seed: int = 1) -> ReferenceScene:
    """Clutter inside a 1.5 m high wall; most of the region stays hidden after
    the initial scans."""
    scene: ReferenceScene = client.reference_scene("s0_walled_cell", seed=seed)
    return scene
