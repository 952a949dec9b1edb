"""`build_scene(kind, rng)`: the scene of one frame, from its kind and a numpy Generator.

The scene (geometry, materials, lights, camera pose, camera-model parameters) depends only on the generator's
draws, never on the render size; `lipjax.data.synthetic.dataset.frame_rngs` seeds the generator of each frame.
"""
from __future__ import annotations

from lipjax.data.synthetic.constants import SYNTHETIC_KINDS
from lipjax.data.synthetic.indoor import indoor_scene
from lipjax.data.synthetic.outdoor import outdoor_scene
from lipjax.data.synthetic.scene import Scene

SCENE_BUILDERS = {"indoor": indoor_scene, "outdoor": outdoor_scene}


def build_scene(kind: str, rng) -> Scene:
    """The scene of `kind` ("indoor": a furnished room; "outdoor": a street) drawn from `rng`."""
    if kind not in SCENE_BUILDERS:
        raise ValueError(f"unknown synthetic kind {kind!r}; expected one of {SYNTHETIC_KINDS}")
    return SCENE_BUILDERS[kind](rng)
