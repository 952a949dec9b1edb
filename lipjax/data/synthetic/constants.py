"""Constants of the synthetic data set.

Kinds, splits and their sizes, the default render size, the reference cameras (NYU v2, KITTI), the outdoor
depth range, the semantic labels (and their int ids, private) and the float32 alias.
"""
from __future__ import annotations

import numpy as np

from lipjax.data.frame import Intrinsics

SYNTHETIC_KINDS = ("indoor", "outdoor")
SPLITS = ("train", "val", "test")

# Default data set sizes. The generator is procedural, so "train" is effectively unbounded: 100k distinct
# scenes is more than any run here consumes; val / test are small and fixed so evaluations are cheap.
TRAIN_SIZE = 100_000
VAL_SIZE = 200
TEST_SIZE = 200
DEFAULT_SIZES = {"train": TRAIN_SIZE, "val": VAL_SIZE, "test": TEST_SIZE}

DEFAULT_HEIGHT = 256
DEFAULT_WIDTH = 320

# NYU Depth v2 (Kinect v1) colour camera, at its native 480x640.
NYU_IMAGE_SIZE = (480, 640)
NYU_INTRINSICS = Intrinsics(fx=518.86, fy=519.47, cx=325.58, cy=253.74)
# KITTI (raw / depth completion, camera 02), at about 375x1242.
KITTI_IMAGE_SIZE = (375, 1242)
KITTI_INTRINSICS = Intrinsics(fx=721.5, fy=721.5, cx=609.6, cy=172.9)
KITTI_CAMERA_HEIGHT_M = 1.65
# Outdoor surfaces farther than this are invalid (depth 0), like returns beyond a LiDAR's range.
RENDER_FAR_CLIP_M = 80.0

# Per-pixel semantic labels in SceneInfo.labels (index into this tuple).
LABELS = (
    "sky", "floor", "wall", "ceiling", "furniture", "object", "road", "sidewalk", "terrain",
    "building", "vehicle", "pole", "vegetation", "person", "fence",
)
(_SKY, _FLOOR, _WALL, _CEILING, _FURNITURE, _OBJECT, _ROAD, _SIDEWALK, _TERRAIN, _BUILDING, _VEHICLE, _POLE,
 _VEGETATION, _PERSON, _FENCE) = range(len(LABELS))

_F32 = np.float32
