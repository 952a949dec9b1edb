"""The numbers and switches of the default path (`lipjax.complete`, `lipjax complete`), in one place.

Each has a one-line reason and, below it, the command that re-derives it (the evidence: the decision record named,
in docs/decisions/), or says that it was set by hand. The modules that use them import them from here:
lipjax.inputs (the scan-line test), lipjax.resolution (the working size), lipjax.spread (residual spreading),
lipjax.crosscheck (the check against the linear fill), lipjax.inference (the switches), lipjax.uncertainty (the
expected error and the support mask) and lipjax.shipped (the default model). How the path uses them, stage by
stage: lipjax.inference.complete_frame, as the plan of the frame says (lipjax.inference.plan_frame).

The measured values were chosen on synthetic frames by rules written before measuring (the decision records); the
others were set by hand. A new value changes the default path's outputs. A leaf: it imports nothing.
"""
from __future__ import annotations

# ---- the model
# lip-any for rooms and streets and every sensor: within 10 % of the per-scene models on Tables I and II (0007)
#   python -m experiments.nyu_200pts --methods lip-any,lip-cnn-indoor,linear
#   python -m experiments.kitti_dc --methods lip-any,lip-cnn-outdoor,linear
DEFAULT_MODEL = "lip-any"

# ---- the pattern of the samples (lipjax.inputs.is_lidar_pattern): set by hand, no benchmark derives them;
# benchmarks.working_resolution stops if one setting's frames differ in pattern, tests/test_inputs.py pins them
SCAN_LINE_ROW_SHARE = 0.5  # scan lines: at least this share of the samples have the next sample in their row
SCAN_LINE_ROW_GAP_PX = 4  # ... the median gap along a row at most this many pixels (a return every 1-2 px) ...
SCAN_LINE_COLUMN_RATIO = 2  # ... and the median gap down a column at least this many times the row gap

# ---- the working size (lipjax.resolution; docs/decisions/0001-working-resolution.md)
# the mean sample spacing (pixels) at which the learned prox runs: the most accurate rule that keeps 10 frames/s
#   python -m benchmarks.working_resolution --model lip-any --frames 6
TARGET_SPACING_PX = 16.0
# the largest working size of LiDAR scan lines and dense maps (pixels): within 0.6 % of the best, at 10 frames/s
#   python -m benchmarks.working_resolution --model lip-any --frames 6
MAX_WORKING_PIXELS = 60_000
# samples per pixel above which a map is a depth camera's or stereo's (KITTI's scans: ~5 %): capped (0017) as scan
# lines are, and not cross-checked (0016)
#   python -m benchmarks.crosscheck --frames 8 --only holes
DENSE = 0.3
# the prox downsamples 8x internally; below this its coarsest features are 8 px wide (set by hand)
MIN_WORKING_SIDE_PX = 64
# the smallest longer side a user may ask for (--max-side): two of the prox's 8 px cells (set by hand)
MIN_MAX_SIDE_PX = 16
# working scales above this run at full size: the resize would cost more than it brings (set by hand)
MIN_SCALE_CHANGE = 0.9
# a frame above this many pixels runs slowly and needs gigabytes at full size: `lipjax complete` suggests --max-side
# (set by hand)
LARGE_FRAME_PIXELS = 2_000_000

# ---- flip averaging (lipjax.inference.flip_averaged)
# on LiDAR scan lines, where the check does not run and leaves the second core free: the suite 0.6350 -> 0.6323 x
# linear, streets with HDL-64 0.404 -> 0.391, the 352x1216 street in two threads 37 -> 42 ms (0020); not on scattered
# samples, where the check's held-out fold takes that core (480x640 with 200 points 36 -> 61 ms with both; fewer than
# 100 samples: 0021)
#   python -m benchmarks.generalisation --frames 8
#   python -m benchmarks.kitti_like_gt --frames 24 --start 8
FLIP_SCAN_LINES = True

# ---- residual spreading after the resize back (lipjax.spread)
# on: the suite without the check 0.708148 -> 0.706272, KITTI-like streets 1.114 -> 1.028 x linear (0018, 0019)
#   python -m benchmarks.kitti_like_gt --frames 24 --start 8
#   python -m benchmarks.generalisation --frames 8 --no-cross-check
SPREAD_RESIDUALS = True
# the Gaussian's sigma for scattered samples, in working pixels (0018)
#   python -m benchmarks.kitti_like_gt --frames 24 --start 8
SIGMA_WORKING_PX = 0.5
# scan lines: (across the lines, along them) in working pixels: their samples lie a pixel or two apart along a line
# and several working pixels apart across the lines (0019)
#   python -m benchmarks.kitti_like_gt --frames 24 --start 8 [--sampler lidar:vlp32]
SCAN_LINE_SIGMAS_WORKING_PX = (1.0, 0.25)
# the fade: delta = DELTA x the Gaussian's centre weight; a lone sample keeps 95 % of its residual (0018)
#   python -m benchmarks.kitti_like_gt --frames 24 --start 8
DELTA = 0.05
# the Gaussian's taps reach ceil(RADIUS_SIGMAS sigma) pixels either side (set by hand: exp(-4.5) = 1 % is cut)
RADIUS_SIGMAS = 3.0

# ---- the check against the linear fill on held-out samples (lipjax.crosscheck)
# on: a model that does not fit the input leans on the linear fill (a street model on rooms 1.48 -> 0.91 x linear),
# the suite 0.662612 -> 0.662305 x linear (0013, 0015); scattered samples only; costs one more run of the model, in
# a second thread (480x640 with 200 points 26 -> 36 ms) at the kept samples' own working size (0014)
#   python -m benchmarks.crosscheck --frames 8
#   python -m benchmarks.generalisation --frames 8
CROSS_CHECK = True
# the samples are held out in this many disjoint folds, each completed from the others; the check stops after the
# first where the model fits (0015)
#   python -m benchmarks.crosscheck --frames 8
FOLDS = 5
# fewer samples: no check (too few held out to test, and every sample is needed) (0013)
#   python -m benchmarks.crosscheck --frames 8
MIN_SAMPLES = 100
# the sign test's level: the model gives way only on this much evidence (set by hand before measuring, 0013)
P_VALUE = 0.05
# which samples fall in which fold: fixed, so that a frame always gives the same depth (set by hand)
SEED = 0

# ---- the expected error and the support mask (lipjax.uncertainty), fitted on the synthetic validation splits
# expected |error| per metre of the nearby samples' depth range and per spacing of distance
#   python -m benchmarks.uncertainty --calibrate
RANGE_GAIN = 0.1217
# expected |error| per metre of depth above the highest samples
#   python -m benchmarks.uncertainty --calibrate
ABOVE_GAIN = 0.1613
# a pixel more than this many sample spacings above the highest sample of its column has no support (set by hand)
ABOVE_SPACINGS = 1.0
# a pixel farther than this many sample spacings from every sample has no support: on the real frames no NYU pixel
# below the top sample is that far, and about 1 % of a KITTI frame's are (set by hand)
#   python -m benchmarks.uncertainty
REACH_SPACINGS = 3.0
