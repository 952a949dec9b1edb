"""Procedural RGB-D scenes: lipjax's embedded default data set (no download, no files).

Every frame is ray-cast, in numpy on the CPU, from an analytic scene seen by a pinhole camera:

* ``indoor``: a room (floor, four walls, ceiling) with furniture built from boxes, cylinders and spheres,
  against the walls and free-standing: cabinets, dressers, wardrobes, bookshelves, desks with chairs,
  tables with chairs, beds, sofas, armchairs, kitchen counters with wall cabinets, fridges, TV stands,
  floor lamps, plants, bins, stacked boxes, balls, wall shelves / frames, and clutter on the tops (books,
  cups, bottles, fruit, monitors, lamps). NYU-v2-like camera (`NYU_INTRINSICS`), 0.95-1.75 m above the
  floor, pitch -26..+5 deg, yaw +-34 deg, roll ~1 deg. Depth about 0.6-8.5 m (at most ~11 m in the
  largest rooms); every pixel is valid (the room is closed).
* ``outdoor``: a straight street, urban / residential / open road: asphalt with lane markings, tyre
  tracks, patches and crosswalks; raised sidewalks with curbs; buildings on both sides (facades with
  windows, shop fronts, stepped roofs; gaps, side yards, a building closing the street); parked and
  moving cars (body, cabin with windows, wheels, lights, plates); street lamps, poles, signs; trees,
  hedges, bushes, fences, pedestrians; distant hills; a sky with clouds and sun glow. KITTI-like camera
  (`KITTI_INTRINSICS`), 1.45-1.85 m above the road (KITTI: 1.65 m), in a lane, yaw +-7 deg, pitch
  -4..+2 deg, roll ~0.7 deg. Sky and surfaces farther than `RENDER_FAR_CLIP_M` (80 m, a LiDAR's range)
  are invalid (depth 0); valid depth starts at ~3-5 m.

RGB: procedural textures with per-object random colours (stripes, checkers, value noise, wood, tiles,
bricks, books, cabinet fronts, facades, foliage, asphalt) and decals that are colour edges but not depth
edges (posters, paintings, documents, whiteboards, doors, windows with curtains or blinds, skirting
boards, rugs, blankets, lane markings, crosswalks, car lights and plates). Shading: Lambertian from one or
two lights (indoor: point lights near the ceiling with soft 1 / (1 + d^2 / r0^2) falloff; outdoor: the
sun, sometimes overcast) plus hemispheric ambient, cast shadows (softened), a Blinn-Phong-like gloss on
some materials, emissive windows / lamps / screens, distance haze outdoors. Camera model: slight optical
blur, random exposure and white balance, vignetting, signal-dependent Gaussian noise, a tone curve with a
highlight shoulder and gamma 2.0-2.4, 8-bit quantisation.

Camera intrinsics: `intrinsics_for(kind, H, W)` scales the reference camera to the render size with
square pixels (largest centred crop of the reference frame with the render's aspect ratio, then an
isotropic resize); see its docstring. `focal_range=(lo, hi)` (render, SyntheticDataset) multiplies its focal
lengths by a factor drawn per frame (`focal_factor`, log-uniform): wider and narrower fields of view of the same
scene from the same pose. `MixedSyntheticDataset(..., far_view_prob=p)` opens a window onto a street in a share p of
its rooms (`far_view.add_far_view`): a room's frame then holds depths of 1-80 m, as photographs of rooms often do.

Conventions:
  * Camera frame: x right, y down, z forward (OpenCV). Pixel (row v, column u) has its centre at (u, v);
    its ray is ((u - cx) / fx, (v - cy) / fy, 1) in the camera frame.
  * `Frame.depth` is z-depth (distance along the optical axis, as in NYU and KITTI), not the ray length:
    float32 metres, 0 = invalid, `Frame.valid = depth > 0`.
  * World frame (exposed through `SceneInfo` from `render_with_info`): y up, floor / road on the plane
    y = 0, x to the right of and z ahead of an unrotated camera. `SceneInfo.camera_to_world` maps
    camera-frame points to world points (its rotation has determinant -1: camera y is down, world y up).
  * Units: metres and pixels.

Determinism: a frame depends only on (kind, split, index, height, width). The scene (geometry, materials,
lights, camera pose, camera-model parameters) comes from a numpy Generator seeded with
sha256("lipjax/synthetic/v1/{kind}/{split}/{index}") and does not depend on the render size; the sensor
noise comes from a second stream of the same seed. Python's salted hash() is never used, so frames are
bit-identical across processes and runs (for a fixed numpy / OpenCV version). Each split has its own
seeds: train, val and test never share a scene.

Approximations made for speed (all deterministic): shadow rays are cast for one pixel in each 2x2 block;
outdoors, objects wholly farther than 70 m cast no shadow; the sky is shaded at 1/4 resolution; objects
covering fewer than 32 pixels get their material's mean colour instead of the full texture.

Speed (`taskset -c 0 .venv/bin/python -m benchmarks.synthetic_fps --frames 40`, one pinned core of the 2-CPU
development machine with the training jobs paused): frames/s of CPU time, 256x320: indoor 30.4 (val split,
unpinned: 27.8), outdoor 25.0 (val: 21.7); 128x160: indoor 55, outdoor 31-34. With a training job beside it
(load ~5): outdoor 256x320 20-22. Outdoor frames cost more: ~140 primitives against ~30 indoors.
Per-primitive numpy calls are batched where the arithmetic allows it without changing a bit of the output
(small parts' camera rays, box and cylinder surfaces, shadow rays: one call per primitive kind); textures
(one call per material) and scene construction (Python) remain per object.

Public API: `render`, `render_with_info`, `SyntheticDataset`, `intrinsics_for`, `focal_factor`, `frame_id`,
`SceneInfo`, `LABELS` and the constants in `__all__`; for a frame drawn another way (lipjax.data.rendered: a window
of the camera) its parts: `frame_rngs` (a frame's two random streams), `build_scene(kind, rng)` (its `Scene`),
`render_scene` (the scene through a camera), `check_kind_split`, `check_size`, `check_focal_range`,
`add_far_view` (a room with a street through a window).

Modules, each importing only those before it: `constants`; `arrays`, `noise`, `colour` (numpy helpers, procedural
noise, colours); `patterns`, `materials` (textures); `geometry`, `primitives` (intersection kernels, primitives);
`scene` (scene description, builder); `camera` (camera model); `culling`;
scene elements, each a builder with its parameter ranges in a frozen dataclass: `room_materials`, `furniture`,
`indoor` (room shell, decals, camera, furniture placement, ceiling lights); `street` (the layout), `road`,
`vegetation`, `buildings`, `cars`, `sky`, `outdoor` (hills, poles and signs, pedestrians, camera);
`build` (`build_scene(kind, rng)`); `visibility`, `surfaces`, `shadows`, `renderer` (ray casting, shading:
`render_scene`, floor reflections on request: `Reflection`); `far_view` (windows onto streets in rooms); `clutter`
(things on a room's floor, on request); `foliage` (porous trees and bushes, on request); `dataset` (the public
entry points: seeds, checks, `render`).
"""
from lipjax.data.synthetic.constants import (
    DEFAULT_HEIGHT,
    DEFAULT_SIZES,
    DEFAULT_WIDTH,
    KITTI_CAMERA_HEIGHT_M,
    KITTI_IMAGE_SIZE,
    KITTI_INTRINSICS,
    LABELS,
    NYU_IMAGE_SIZE,
    NYU_INTRINSICS,
    RENDER_FAR_CLIP_M,
    SPLITS,
    SYNTHETIC_KINDS,
    TEST_SIZE,
    TRAIN_SIZE,
    VAL_SIZE,
)
from lipjax.data.synthetic.dataset import (
    SceneInfo,
    SyntheticDataset,
    check_focal_range,
    check_kind_split,
    check_size,
    focal_factor,
    frame_rngs,
    intrinsics_for,
    render,
    render_with_info,
    frame_id,
)
from lipjax.data.synthetic.far_view import add_far_view
from lipjax.data.synthetic.renderer import render_scene
from lipjax.data.synthetic.scene import Scene
from lipjax.data.synthetic.build import build_scene

__all__ = [
    "SYNTHETIC_KINDS",
    "SPLITS",
    "TRAIN_SIZE",
    "VAL_SIZE",
    "TEST_SIZE",
    "DEFAULT_SIZES",
    "DEFAULT_HEIGHT",
    "DEFAULT_WIDTH",
    "NYU_IMAGE_SIZE",
    "NYU_INTRINSICS",
    "KITTI_IMAGE_SIZE",
    "KITTI_INTRINSICS",
    "KITTI_CAMERA_HEIGHT_M",
    "RENDER_FAR_CLIP_M",
    "LABELS",
    "Scene",
    "SceneInfo",
    "SyntheticDataset",
    "add_far_view",
    "build_scene",
    "check_focal_range",
    "check_kind_split",
    "check_size",
    "focal_factor",
    "frame_rngs",
    "intrinsics_for",
    "render",
    "render_scene",
    "render_with_info",
    "frame_id",
]
