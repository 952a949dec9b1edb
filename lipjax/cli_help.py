"""What the `lipjax` command line shows before it runs anything: the option values it offers (choices, defaults
named in the help) and the long help of `lipjax complete`, in plain Python, so that building the parser loads no
JAX and `lipjax --help` answers at once (lipjax.cli imports the library inside each command).

Each value here is a copy of the library's own (the module named beside it); tests/test_cli.py checks that they
are equal, so a change there fails the tests until it is made here too.
"""
from __future__ import annotations

import types

OUT_FORMATS = ("npy", "png", "color.png")  # lipjax.data.folder.OUT_FORMATS
SOURCES = ("synthetic", "rendered", "nyu_h5", "nyu_tfds", "kitti_dc", "kitti_selection", "kitti_odometry",
           "tartanair", "folder")  # lipjax.data.sources.SOURCES
NO_PROTOCOL = "none"  # lipjax.data.sources.NO_PROTOCOL
PROTOCOLS = ("kitti_paper", "kitti_selection", "nyu_ma", "nyu_paper", "synthetic_indoor", "synthetic_outdoor",
             "tartanair")  # sorted(lipjax.data.protocols.PROTOCOLS)
SPLITS = ("train", "val", "test")  # lipjax.data.synthetic.SPLITS
SYNTHETIC_KINDS = ("indoor", "outdoor")  # lipjax.data.synthetic.SYNTHETIC_KINDS
DEFAULT_COLUMNS = ("rmse_m", "mae_m", "rel", "delta1_pct", "delta2_pct", "delta3_pct", "irmse_1_per_km",
                   "imae_1_per_km", "mae_sampled_m", "mae_unsampled_m", "mae_vs_input_m",
                   "ms_per_frame")  # lipjax.evaluate.DEFAULT_COLUMNS
CLASSICAL = ("nearest", "linear", "ip_basic", "ip_basic_multiscale", "ip_basic_adaptive", "colorization",
             "lip-wavelet")  # tuple(lipjax.methods.CLASSICAL)
# `lipjax train`'s defaults: lipjax.train.folder's FOLDER_STEPS, FOLDER_BATCH_SIZE, FOLDER_DATA.crop, .num_workers;
# with --self-supervised, lipjax.train.adapt's ADAPT_STEPS
TRAINING = types.SimpleNamespace(steps=2000, batch_size=8, crop=(128, 160), workers=2, adapt_steps=500)
TRAIN_STEPS_HELP = f"training steps (default {TRAINING.steps}; {TRAINING.adapt_steps} with --self-supervised)"

COMPLETE_HELP = """\
Completes the sparse depth of your own frames.

Inputs and outputs:
  --rgb     colour image (.png / .jpg), or a folder of them.
  --depth   sparse depth aligned pixel for pixel with the RGB image, 0 = no sample, or a folder of them:
              .png  16-bit, metres = value / S with S = --depth-scale (KITTI 256, NYU 1000, TUM 5000; also the
                    names kitti, nyu, tum). A PNG holds no unit, so --depth-scale is required for PNG input.
              .npy  float metres (never scaled; --depth-scale then only sets the scale of .png output).
  --lidar   instead of --depth: a LiDAR sweep (KITTI .bin, .npy (N, >=3) x y z metres, or .pcd), projected into
            the image with --calib (the nearest point per pixel): KITTI object calib .txt, a KITTI raw date
            folder, a KITTI odometry calib.txt, or a rig .txt/.yaml with K and T_cam_from_lidar; --camera picks
            KITTI's image (2 = image_2, the default; 3 = image_3). The calibration's intrinsics serve --ply too.
  --out     the extension chooses the format:
              X.npy        float32 metres.
              X.png        16-bit PNG, value = round(metres * S), S = --depth-scale, or 256 when none was given
                           (npy input); values above 65535 are clipped, with a warning.
              X.color.png  8-bit colour picture (turbo colour map) over --color-range; by default 0 m to the
                           model's max depth (10 m indoor, 85 m outdoor), or to the output's 99th percentile
                           when that is beyond the model's range or under a quarter of it (with folders, the
                           first frame's); black = no depth.
            With folders, OUT is a folder and gets one file per frame, <rgb stem>.<--out-format>
            (npy | png | color.png; default: png when the depth inputs are PNG, else npy).
            Folder frames are paired by file stem, or, when no stem matches, by the number the stems end with
            (rgb_00050.jpg <-> sync_depth_00050.png). The next frames are read while the model runs (on two
            frames at once after the first), outputs are written in the background, and the summary line gives
            frames/s. A frame that fails stops the run with the frames before it written whole and nothing of
            itself or after it (files are renamed into place once written). The folders of --out, --ply and
            --uncertainty are checked writable before anything runs.
  --ply     also write the completed depth as a coloured point cloud (camera frame: x right, y down, z forward,
            metres); needs the intrinsics of the RGB image. A folder when --rgb is one.
  --uncertainty  also write the expected absolute error of the completed depth, metres:
            X.npy float32 metres, or X.png a colour picture (dark blue 0 m to dark red >= --max-uncertainty, or
            10 % of the model's max depth); a folder of <rgb stem>.npy when --rgb is one.
  --max-uncertainty M  set the depth to 0 (no depth) where the expected error is above M metres, in --out and
            in --ply; with no support (sky, above the top LiDAR beam) the expected error is the frame's highest.
  --threads N  run on N CPU cores: every thread of the process (XLA's, OpenCV's, the frame readers') is pinned
            to N of the cores it may use, as `taskset` does (Linux; OpenCV's threads only elsewhere). With this
            JAX, XLA_FLAGS="--xla_cpu_multi_thread_eigen=false intra_op_parallelism_threads=N" does NOT limit
            XLA's threads; `taskset -c 0,1 lipjax ...` works as well and picks the cores.

Where depth is written: by default, what the model or method returns, at every pixel it gives depth: the same
map as the Python API's complete(). A learned model gives depth everywhere (0 only where its estimate is not above
0); a hand-crafted method runs as published and leaves 0 where it does by design (ip_basic and ip_basic_multiscale:
pixels out of reach of their dilations, e.g. above the top LiDAR beam). The summary line says how many pixels are 0.
  --fill-all  depth at every pixel: where the model or method left 0, the depth of the nearest pixel with depth
            (a nearest fill of its own output). --max-uncertainty still applies.
  --blank-unsupported  0 (no depth) where no sample supports the completion, in --out and --ply: pixels more
            than one sample spacing s above the highest sample of their column (sky, above the top LiDAR beam),
            and pixels farther than 3 s from every sample (s = sqrt(area of the samples' bounding box / their
            number), pixels). --uncertainty keeps every pixel. Not with --fill-all.

Image size: any. A learned model runs at the working size where its samples lie about as far apart in pixels as
in training, at most 60,000 pixels for LiDAR scan lines (sizes HxW: 200 points on 480x640 run at 196x261; a
64-beam KITTI scan at 132x455; dense scattered samples at full size); a
new size costs one compilation. Below full size the RGB is area-resized; each measured depth pixel is moved to the
pixel of the small grid it falls in, keeping its value (the nearest one wins where several meet; depths are never
averaged); the result is resized back (bilinear). A learned model's measured pixels are then set to their measured
values exactly, at any size. A hand-crafted method (--model ip_basic, linear, ...) runs at full size and its output
is written as the method returns it (IP-Basic, as published, replaces background returns seen through gaps in the
foreground); run below full size (--max-side), its measured pixels are set back too.
`--max-side N` overrides the working size: the longer side becomes at most N pixels. A learned model also runs the
flipped frame of LiDAR scan lines and averages the two (more accurate, twice the model's work, on the core the check
leaves free); `--flip` does so on every input, `--no-flip` on none.
With 100 scattered samples or more (not LiDAR scan lines) a learned model is checked against the linear fill on
every sample, held out of its input in five folds, and leans on the fill on frames where it is the worse of the two;
`--no-cross-check` runs the model alone, once instead of twice (six times where the first fold goes against it).
`--explain` prints each frame's plan and stops: no model runs and nothing is written (no --out needed). A line per
decision: the model; the samples' pattern (scan lines; scattered; few points, under 100; dense, a depth camera's
map with holes), their number and spacing; the working size; the initial estimate; flip averaging; residual
spreading; the check against the linear fill; whether the measured pixels are set back.

Errors you can act on (unreadable files, misaligned or empty depth, a PNG without scale, unknown model, an output
folder that cannot be written, ...) print one line "lipjax: error: ..." and exit with status 1; set LIPJAX_DEBUG=1
to see the traceback instead. A frame above 2 Mpixel run without --max-side gets a one-line hint.
"""
"""The description of `lipjax complete` in its --help: the inputs, outputs and options of files.complete_files."""


def depth_scale(text: str) -> float:
    """argparse type of --depth-scale (256, 1000, kitti, nyu, ...): lipjax.data.folder.parse_depth_scale, imported
    when an argument is parsed, not when the parser is built."""
    from lipjax import console
    from lipjax.data.folder import parse_depth_scale

    return console.argument_type(parse_depth_scale)(text)
