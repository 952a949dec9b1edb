"""lipjax: depth completion of your own frames (an RGB image and sparse depth or a LiDAR sweep), evaluation,
fine-tuning and export. Depth is in metres; 0 means no depth.

    lipjax complete --rgb IMG --depth SPARSE [--depth-scale S] [--model NAME|PATH] [--iterations K] --out OUT
                    [--max-side N] [--ply FILE (--intrinsics fx fy cx cy | --intrinsics-file F)]
                    [--uncertainty FILE] [--max-uncertainty M] [--fill-all]
    lipjax complete --rgb IMG --lidar SWEEP --calib FILE [--camera 2] --out OUT ...   (the sweep projected first)
    lipjax project --rgb IMG --lidar SWEEP --calib FILE [--camera 2] --out SPARSE.npy|.png   (the sparse input only)
    lipjax evaluate [--model NAME|PATH ...] [--data synthetic-indoor|synthetic-outdoor|FOLDER] [--sampler SPEC]
    lipjax evaluate [--model NAME|PATH ...] --source NAME --root DIR [--raw-root DIR] [--split val]  (as training reads)
    lipjax evaluate [--model NAME|PATH ...] --source synthetic [--kind indoor|outdoor] [--split val]
    lipjax export [--model NAME|PATH] --height H --width W [--batch B] --out FILE.stablehlo
    lipjax train --data FOLDER --out MODEL [--depth-scale S] [--init NAME|PATH] [--steps N]   (fine-tune on your frames)
    lipjax data render --kind indoor|outdoor --split train --count N --out DIR [--workers W]
    lipjax models
    lipjax --version

Run `lipjax COMMAND --help` for a command's options.

`complete`, inputs and outputs:
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
            (rgb_00050.jpg <-> sync_depth_00050.png).
  --ply     also write the completed depth as a coloured point cloud (camera frame: x right, y down, z forward,
            metres); needs the intrinsics of the RGB image. A folder when --rgb is one.
  --uncertainty  also write the expected absolute error of the completed depth, metres:
            X.npy float32 metres, or X.png a colour picture (dark blue 0 m to dark red >= --max-uncertainty, or
            10 % of the model's max depth); a folder of <rgb stem>.npy when --rgb is one.
  --max-uncertainty M  set the depth to 0 (no depth) where the expected error is above M metres, in --out and
            in --ply; with no support (sky, above the top LiDAR beam) the expected error is the frame's highest.
  --fill-all  write the dense map, depth also where no sample supports it (--max-uncertainty still applies).
            Without it, those pixels are 0 (no depth) in --out and --ply: pixels more than one sample spacing s
            above the highest sample of their column (sky, above the top LiDAR beam), and pixels farther than 3 s
            from every sample (s = sqrt(area of the samples' bounding box / their number), pixels). --uncertainty
            keeps every pixel.

Image size: any. A learned model runs at the working size where its samples lie about as far apart in pixels as
in training (200 points on 640x480 run at about half size; a 64-beam scan at full size); a new size costs one
compilation. Below full size the RGB is area-resized; each measured depth pixel is moved to the pixel of the
small grid it falls in, keeping its value (the nearest one wins where several meet; depths are never averaged);
the result is resized back (bilinear) and the measured pixels are then set to their measured values exactly.
`--max-side N` overrides the working size: the longer side becomes at most N pixels.

Errors you can act on (unreadable files, misaligned or empty depth, a PNG without scale, unknown model, ...)
print one line "lipjax: error: ..." and exit with status 1; set LIPJAX_DEBUG=1 to see the traceback instead.
A frame above 2 Mpixel run without --max-side gets a one-line hint.
"""
# For developers: each subcommand is one `_cmd_*` function registered in `build_parser`; it parses its arguments
# and calls the library (lipjax.inference, lipjax.data.folder, lipjax.pointcloud, lipjax.evaluate, lipjax.export).
from __future__ import annotations

import argparse
import dataclasses
import sys
from pathlib import Path

from lipjax import console

PROG = "lipjax"
DEFAULT_PNG_OUT_SCALE = 256.0
# `lipjax --help` shows the overview; `lipjax complete --help` the details of `complete`, below it.
_OVERVIEW, _, _COMPLETE_DETAILS = __doc__.partition("`complete`, inputs and outputs:\n")
CLIError = console.UserError


def _warn(message: str) -> None:
    console.warn(PROG, message)


# ------------------------------------------------------------------------------------------- argument types


def _depth_scale(text: str) -> float:
    from lipjax.data.folder import KNOWN_DEPTH_SCALES

    if text.lower() in KNOWN_DEPTH_SCALES:
        return KNOWN_DEPTH_SCALES[text.lower()]
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"expected a number or one of {sorted(KNOWN_DEPTH_SCALES)}, got {text!r}") from None
    if not value > 0:
        raise argparse.ArgumentTypeError(f"must be > 0, got {text}")
    return value


def _intrinsics_from_args(args):
    """The checked Intrinsics of --intrinsics / --intrinsics-file, or None when neither was given."""
    from lipjax.data.folder import read_intrinsics_txt
    from lipjax.pointcloud import as_intrinsics

    if getattr(args, "intrinsics", None):
        return as_intrinsics(args.intrinsics)
    if getattr(args, "intrinsics_file", None):
        return read_intrinsics_txt(args.intrinsics_file, getattr(args, "camera", 2))
    return None


def _model_max_depth(completer) -> float:
    """The depth range a model was made for (10 m indoor, 85 m outdoor), 10 m when it does not say."""
    from lipjax.inference import Completer
    from lipjax.interfaces import SCENE_MAX_DEPTH_M

    # every learned model states it (lipjax.interfaces); classical fills have none
    return completer.config.max_depth_m if isinstance(completer, Completer) else SCENE_MAX_DEPTH_M["indoor"]


# ------------------------------------------------------------------------------------------------ commands


def _cmd_complete(args) -> int:
    from lipjax.data.folder import check_one_depth_format, output_format, pair_frames, read_frame, write_depth
    from lipjax.data.lidar import read_lidar_frame
    from lipjax.inference import LARGE_FRAME_PIXELS, complete_frame, frame_size
    from lipjax.inputs import scene_reason
    from lipjax.methods import get_completer
    from lipjax.pointcloud import backproject_rgbd, write_ply
    from lipjax.uncertainty import drop_uncertain, expected_error, mask_unsupported, write_uncertainty
    from lipjax.viz import fitting_range

    if (args.depth is None) == (args.lidar is None):
        raise CLIError("give the sparse depth as --depth SPARSE, or a LiDAR sweep as --lidar SWEEP --calib FILE")
    if (args.lidar is None) != (args.calib is None):
        raise CLIError("--lidar SWEEP and --calib FILE go together: the sweep, and its calibration with the camera")
    rgb_path, out, ply = Path(args.rgb), Path(args.out), args.ply and Path(args.ply)
    depth_path = Path(args.depth or args.lidar)
    if args.lidar and rgb_path.is_dir():
        raise CLIError("--lidar takes one sweep with one --rgb image, not a folder")
    unc = args.uncertainty and Path(args.uncertainty)
    if args.max_uncertainty is not None and not args.max_uncertainty >= 0:
        raise CLIError(f"--max-uncertainty {args.max_uncertainty:g}: must be >= 0 metres")
    intrinsics = _intrinsics_from_args(args)
    if ply and intrinsics is None and not args.lidar:
        raise CLIError("--ply needs the camera intrinsics: --intrinsics fx fy cx cy or --intrinsics-file F")
    if args.color_range and not args.color_range[1] > args.color_range[0]:
        raise CLIError(f"--color-range {args.color_range[0]:g} {args.color_range[1]:g}: MAX_M must be > MIN_M")
    for p in (rgb_path, depth_path):
        if not p.exists():
            raise CLIError(f"{p}: no such file or folder")
    if rgb_path.is_dir() != depth_path.is_dir():
        raise CLIError("--rgb and --depth must both be files or both be folders")
    if rgb_path.is_dir():
        pairs = [(r, d) for _, r, d in pair_frames(rgb_path, depth_path)]
        check_one_depth_format([d for _, d in pairs])
        for flag, path in (("--out", out), ("--ply", ply), ("--uncertainty", unc)):
            if path and path.exists() and not path.is_dir():
                raise CLIError(f"{flag} {path}: with input folders, {flag} must be a folder")
        fmt = args.out_format or ("png" if pairs[0][1].suffix.lower() == ".png" else "npy")
        npy_in = pairs[0][1].suffix.lower() == ".npy"
        jobs = [(r, d, out / f"{r.stem}.{fmt}", ply / f"{r.stem}.ply" if ply else None) for r, d in pairs]
    else:
        if args.out_format:
            raise CLIError("--out-format is for folders; for one frame the extension of --out chooses the format")
        fmt = output_format(out)
        npy_in = depth_path.suffix.lower() != ".png"
        jobs = [(rgb_path, depth_path, out, ply or None)]
        if unc and unc.suffix.lower() not in (".npy", ".png"):
            raise CLIError(f"--uncertainty {unc}: use .npy (metres) or .png (colour picture)")
    out_scale = args.depth_scale or DEFAULT_PNG_OUT_SCALE
    if args.depth_scale and npy_in and fmt != "png":
        _warn(f"--depth-scale {args.depth_scale:g} is ignored: {'the sweep is' if args.lidar else '.npy depth is'} "
              "metres, never scaled (--depth-scale applies to .png depth, in and out)")

    completer = None  # loaded after the first frame is read: input errors come before the slow model load
    color_range = tuple(args.color_range) if args.color_range else None  # else fitted to the first frame
    unsupported = pixels = 0  # pixels set to 0 for want of support, and all pixels, over all frames
    progress = jobs
    if len(jobs) > 1 and not args.quiet:
        from tqdm import tqdm

        progress = tqdm(jobs, desc=f"{PROG} complete", unit="frame", file=sys.stderr)
    for rgb_file, depth_file, out_file, ply_file in progress:
        if args.lidar:
            rgb, sparse, calib_intrinsics = read_lidar_frame(rgb_file, depth_file, args.calib, args.camera)
            intrinsics = intrinsics or calib_intrinsics
        else:
            rgb, sparse = read_frame(rgb_file, depth_file, args.depth_scale)
        if completer is None:
            completer = get_completer(args.model, args.iterations, sparse=sparse)
            if args.model is None and not args.quiet:
                scene, why = scene_reason(sparse)
                print(f"model: {completer.name}, the default for {scene} input ({why}); "
                      "choose another with --model", file=sys.stderr)
            h, w = frame_size(completer, sparse, args.max_side)
            if args.max_side is None and h * w > LARGE_FRAME_PIXELS:
                _warn(f"{rgb_file}: a {sparse.shape[1]}x{sparse.shape[0]} frame ({sparse.size / 1e6:.1f} Mpixel) runs "
                      "slowly and needs gigabytes at full size; --max-side 1024 runs it downsized (--max-side 416 "
                      "with the shipped outdoor models, their training scale)")
        dense = complete_frame(completer, rgb, sparse, args.max_side)
        if unc or args.max_uncertainty is not None:
            u = expected_error(sparse, dense)
            if unc:
                write_uncertainty(unc / f"{rgb_file.stem}.npy" if rgb_path.is_dir() else unc, u,
                                  args.max_uncertainty or 0.1 * _model_max_depth(completer))
            if args.max_uncertainty is not None:
                dense = drop_uncertain(dense, u, args.max_uncertainty)
        if not args.fill_all:
            masked = mask_unsupported(dense, sparse)
            unsupported, pixels = unsupported + int(((masked == 0) & (dense > 0)).sum()), pixels + dense.size
            dense = masked
        if color_range is None:
            color_range = fitting_range(dense, _model_max_depth(completer))
        write_depth(out_file, dense, fmt, out_scale, color_range)
        if ply_file is not None:
            ply_file.parent.mkdir(parents=True, exist_ok=True)
            write_ply(ply_file, *backproject_rgbd(dense, rgb, intrinsics))
    if not args.quiet:
        if len(jobs) == 1:
            wrote = f"{jobs[0][2]}" + (f" and {jobs[0][3]}" if jobs[0][3] else "")
        else:
            wrote = f"{len(jobs)} frame(s) to {out}"
        notes = [f"{100 * unsupported / pixels:.1f} % of the pixels without support set to 0 (--fill-all keeps "
                 "them)"] if unsupported else []
        if fmt == "color.png" and not args.color_range:
            notes.append(f"colours 0-{color_range[1]:.3g} m")
        print(f"wrote {wrote}" + (f": {'; '.join(notes)}" if notes else ""), file=sys.stderr)
    return 0


def _data_frames(args, protocol):
    """(the frames of --data: the synthetic split or FOLDER, no protocol applied yet; their sampler; the sampler's
    spec; the data in words; the protocol whose depth range applies, or None)."""
    from lipjax.data import protocols
    from lipjax.evaluate import DEFAULT_SAMPLER, open_folder

    if args.data in ("synthetic-indoor", "synthetic-outdoor"):
        from lipjax.data.sampling import sampler_from_spec
        from lipjax.data.synthetic import SyntheticDataset

        kind, spec = args.data.split("-")[1], args.sampler or DEFAULT_SAMPLER
        height, width = args.size or (None, None)
        size_kw = {"height": height, "width": width} if args.size else {}
        return (SyntheticDataset(kind, args.split or "test", **size_kw), sampler_from_spec(spec), spec, args.data,
                protocol or protocols.get_protocol(f"synthetic_{kind}"))
    root = Path(args.data)
    if not root.is_dir():
        raise CLIError(f"--data {args.data}: not synthetic-indoor, synthetic-outdoor or a folder")
    if args.split == "test":
        raise CLIError(f"--split test: a folder has train and val frames (--split train|val), or leave --split out "
                       f"to score every frame of {root}")
    frames, sampler, spec, which = open_folder(root, args.split, sampler=args.sampler, depth_scale=args.depth_scale,
                                               intrinsics=_intrinsics_from_args(args))
    return frames, sampler, spec, f"{args.data}, {which}", protocol


def _cmd_evaluate(args) -> int:
    from lipjax.data import protocols
    from lipjax.data.sources import NO_PROTOCOL, OWN_INPUT
    from lipjax.evaluate import DEFAULT_COLUMNS, DEFAULT_SAMPLER, evaluate, markdown_table, open_eval_source, save_json
    from lipjax.methods import get_completer

    if args.source is None and (args.root is not None or args.raw_root is not None):
        raise CLIError("--root and --raw-root go with --source NAME; --data takes the folder itself")
    if args.kind is not None and args.source != "synthetic":
        raise CLIError(f"--kind goes with --source synthetic; --source rendered reads the kind from the render's "
                       f"index.json, and --data synthetic-{args.kind} names it itself")
    if args.source is not None:
        if args.root is None and args.source != "synthetic":
            raise CLIError(f"--source {args.source} needs --root DIR, the folder holding the data set")
        if args.size is not None:
            raise CLIError(f"--size is for --data synthetic-*; --source {args.source} reads its frames at their "
                           "own (training) size")
        if args.intrinsics is not None or args.intrinsics_file is not None:
            raise CLIError(f"--intrinsics / --intrinsics-file are for --data FOLDER; --source {args.source} reads "
                           "the data set's own")
        if args.split not in (None, "train", "val"):
            raise CLIError(f"--split {args.split}: with --source, the split is train or val")
        if args.source == "rendered" and args.split is not None:
            raise CLIError("--split: --source rendered evaluates the frames in --root (their split is the render's); "
                           "drop --split")
        split, spec = args.split or "val", args.sampler or DEFAULT_SAMPLER
        source, range_from = open_eval_source(args.source, args.root, split, sampler=spec,
                                              protocol=args.protocol, raw_root=args.raw_root,
                                              depth_scale=args.depth_scale, kind=args.kind)
        dataset, sampler = source.dataset, source.sampler  # protocol applied
        if args.source == "rendered":
            from lipjax.data.rendered import RenderedMixture, open_rendered

            render = open_rendered(args.root)
            parts = render.parts if isinstance(render, RenderedMixture) else [render]
            data_name = f"rendered {' + '.join(f'{p.kind}/{p.split}' for p in parts)} ({args.root})"
        else:
            kind = f" {args.kind or 'indoor'}" if args.source == "synthetic" else ""
            data_name = f"{args.source}{kind} {split}" + (f" ({args.root})" if args.root else "")
    else:
        protocol = protocols.get_protocol(args.protocol) if args.protocol not in (None, NO_PROTOCOL) else None
        dataset, sampler, spec, data_name, range_from = _data_frames(args, protocol)
        if protocol is not None:
            dataset = protocols.ProtocolView(dataset, protocol)
    min_depth = args.min_depth_m if args.min_depth_m is not None else (range_from.min_depth_m if range_from else 0.0)
    max_depth = args.max_depth_m if args.max_depth_m is not None else (range_from.max_depth_m if range_from else None)
    if max_depth is None:
        raise CLIError("give the evaluated depth range: --max-depth-m M (e.g. 10 indoors, 80 outdoors) "
                       "or --protocol NAME")
    columns = tuple(c.strip() for c in args.columns.split(",")) if args.columns else DEFAULT_COLUMNS
    results = {}
    for model in args.model or [None]:  # the default model: the one the first frame's input suggests
        completer = get_completer(model, args.iterations, sparse=None if model else sampler(dataset[0], args.seed))
        label = model if model is not None else ("untrained" if completer.name == "random" else completer.name)
        results[label] = evaluate(completer, dataset, sampler, min_depth_m=min_depth, max_depth_m=max_depth,
                                  limit=args.limit, progress=not args.quiet, seed=args.seed)
    n = next(iter(results.values())).num_images
    own = " (the data's own sparse maps)" if spec.split(":")[0] == OWN_INPUT else ""
    print(f"data: {data_name} ({n} frames), sampler: {spec}{own}, depth range: ({min_depth:g}, {max_depth:g}] m")
    print()
    print(markdown_table(results, columns=columns))
    if args.json:
        save_json(results, args.json)
    return 0


def _cmd_export(args) -> int:
    from lipjax.export import export_completer, save_exported
    from lipjax.methods import get_completer

    completer = get_completer(args.model, args.iterations)
    platforms = tuple(p.strip() for p in args.platforms.split(",")) if args.platforms else None
    exported = export_completer(completer, args.batch, args.height, args.width, platforms=platforms)
    try:
        path = save_exported(exported, args.out)
    except ImportError as exc:
        raise CLIError(str(exc)) from exc
    if not args.quiet:
        shape = (args.batch, args.height, args.width)
        z0 = (f", z0 float32 {shape} m (the model's {completer.config.initial_estimate} fill of sparse, computed "
              "outside: lipjax.model.host_initial_estimate)") if len(exported.in_avals) == 3 else ""
        print(f"wrote {path} ({path.stat().st_size} bytes): rgb uint8 {shape + (3,)}, sparse float32 {shape} m{z0} "
              f"-> depth m; platforms {list(exported.platforms)}", file=sys.stderr)
    return 0


def _cmd_models(args) -> int:
    from lipjax import model_io
    from lipjax.inputs import DEFAULT_MODELS

    if not model_io.available():
        print(f"no shipped models in {model_io.WEIGHTS_DIR}; `lipjax complete` then uses an untrained model. "
              "Train one with `python -m experiments.train --config lip_cnn_indoor`, or pass --model PATH.")
        return 0
    print(model_io.table(DEFAULT_MODELS))
    print("\nDEFAULT: lipjax complete picks the indoor default for scattered samples, the outdoor default for LiDAR "
          "scan lines\nor a median sample depth over 12 m; --model NAME overrides it. TYPE: LIP and its prox, or an "
          "end-to-end network.")
    return 0


def _cmd_data_render(args) -> int:
    from lipjax.data.rendered import render_to_disk

    try:
        out = render_to_disk(args.kind, args.split, args.count, args.out, height=args.height, width=args.width,
                             window=args.window, workers=args.workers, progress=not args.quiet)
    except (KeyboardInterrupt, SystemExit) as stop:  # Ctrl-C, SIGTERM: the workers are stopped already
        print(f"{PROG}: render stopped; its finished shards stay in {args.out}, and the same command finishes it",
              file=sys.stderr)
        return 130 if isinstance(stop, KeyboardInterrupt) else stop.code
    print(f"rendered {args.count} {args.kind}/{args.split} frames to {out}")
    return 0


def _cmd_train(args) -> int:
    from lipjax import model_io
    from lipjax.train.folder import default_init, folder_config
    from lipjax.train.run import run

    data = {"root": args.data, "depth_scale": args.depth_scale, "num_workers": args.workers,
            **({"crop": tuple(args.crop)} if args.crop else {}),
            **({"train_sampler": args.sampler} if args.sampler else {})}
    init = args.init
    if init is None:
        init, scene, why = default_init(**data)
        if not args.quiet:
            print(f"init: {init}, the default for {scene} input ({why}); choose another with --init", file=sys.stderr)
    name = Path(args.out).name
    config = folder_config(model_io.load(init)[0], init, name=name, **data)
    config = dataclasses.replace(config, batch_size=args.batch_size, **({"g_steps": args.steps} if args.steps else {}))
    run(config, args.workdir or f"runs/train-{name}", export=args.out, progress=not args.quiet, validate_start=True)
    return 0


def _cmd_project(args) -> int:
    from lipjax.data.folder import output_format, write_depth
    from lipjax.data.lidar import read_lidar_frame

    fmt = output_format(args.out)
    _, sparse, _ = read_lidar_frame(args.rgb, args.lidar, args.calib, args.camera)
    write_depth(args.out, sparse, fmt, args.depth_scale or DEFAULT_PNG_OUT_SCALE, (0.0, float(sparse.max())))
    if not args.quiet:
        n, (h, w) = int((sparse > 0).sum()), sparse.shape
        print(f"wrote {args.out}: depth at {n} pixels ({100 * n / sparse.size:.1f} % of {w}x{h}), "
              f"{sparse[sparse > 0].min():.2f} to {sparse.max():.2f} m", file=sys.stderr)
    return 0


# ------------------------------------------------------------------------------------------------- parsing


def _add_lidar_args(parser, required: bool) -> None:
    """--lidar, --calib, --camera: of `project`, and of `complete` as the alternative to --depth."""
    parser.add_argument("--lidar", required=required, default=None, metavar="SWEEP",
                        help="LiDAR sweep: KITTI .bin, .npy (N, >=3) x y z metres, or .pcd")
    parser.add_argument("--calib", required=required, default=None, metavar="FILE",
                        help="KITTI object calib .txt, KITTI raw date folder, KITTI odometry calib.txt, or a rig "
                             ".txt/.yaml with K and T_cam_from_lidar")
    parser.add_argument("--camera", type=int, default=2, metavar="N",
                        help="the KITTI camera of --rgb: 2 (image_2, default) or 3")


def _add_project_parser(sub) -> None:
    p = sub.add_parser("project", help="project a LiDAR sweep into a camera image: the sparse depth input",
                       description="Projects a LiDAR sweep into the camera of --rgb (the nearest point per pixel; "
                                   "depth = z in the camera frame, metres) and writes the sparse depth image.")
    _add_lidar_args(p, required=True)
    p.add_argument("--rgb", required=True, help="the camera's image (gives the size)")
    p.add_argument("--out", required=True,
                   help="SPARSE.npy (float32 metres) | .png (16-bit, value = metres * --depth-scale) | .color.png")
    p.add_argument("--depth-scale", type=_depth_scale, default=None, metavar="S",
                   help=f"PNG value per metre of .png output (default {DEFAULT_PNG_OUT_SCALE:g}, KITTI's)")
    p.add_argument("-q", "--quiet", action="store_true", help="no summary line")
    p.set_defaults(func=_cmd_project)


def build_parser() -> argparse.ArgumentParser:
    from lipjax import __version__
    from lipjax.data import protocols
    from lipjax.data.folder import OUT_FORMATS
    from lipjax.data.sources import NO_PROTOCOL, SOURCES
    from lipjax.evaluate import DEFAULT_COLUMNS

    parser = console.ArgumentParser(prog=PROG, description=_OVERVIEW,
                                    formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--version", action="version", version=f"{PROG} {__version__}")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")

    c = sub.add_parser("complete", help="complete sparse depth of your own frames",
                       description="Completes the sparse depth of your own frames.\n\nInputs and outputs:\n"
                                   + _COMPLETE_DETAILS, formatter_class=argparse.RawDescriptionHelpFormatter)
    c.add_argument("--rgb", required=True, help="colour image (.png/.jpg) or a folder of them")
    c.add_argument("--depth", default=None,
                   help="sparse depth: 16-bit .png (needs --depth-scale) or .npy metres; or a folder")
    _add_lidar_args(c, required=False)
    c.add_argument("--depth-scale", type=_depth_scale, default=None, metavar="S",
                   help="PNG value per metre: 256 (kitti), 1000 (nyu), 5000 (tum); also the scale of .png output "
                        "(default 256)")
    c.add_argument("--model", default=None, help="shipped model name (lipjax models) or saved model path "
                   "(also a classical fill: nearest, linear, ip_basic, colorization, lip-wavelet)")
    c.add_argument("--iterations", type=console.positive_int, default=None, metavar="K",
                   help="run the first K ADMM iterations")
    c.add_argument("--out", required=True, help="X.npy | X.png | X.color.png, or a folder with folder inputs")
    c.add_argument("--out-format", choices=OUT_FORMATS, default=None, help="per-frame format with folder inputs")
    c.add_argument("--max-side", type=console.positive_int, default=None, metavar="N",
                   help="run frames downsized to this longer side (default: the working size of the samples)")
    c.add_argument("--color-range", type=float, nargs=2, default=None, metavar=("MIN_M", "MAX_M"),
                   help="metres mapped onto the colour map of .color.png (default 0 .. the model's max depth)")
    c.add_argument("--ply", default=None, help="also write a coloured point cloud (.ply; a folder with folder inputs)")
    intr = c.add_mutually_exclusive_group()
    intr.add_argument("--intrinsics", type=float, nargs=4, metavar=("FX", "FY", "CX", "CY"),
                      help="pixels, of the RGB image")
    intr.add_argument("--intrinsics-file", default=None, metavar="F",
                      help='"fx fy cx cy", the 9 numbers of K, or a calibration file (as --calib)')
    c.add_argument("--uncertainty", default=None, metavar="FILE",
                   help="also write the expected absolute error: .npy metres or .png picture (a folder with folders)")
    c.add_argument("--max-uncertainty", type=float, default=None, metavar="M",
                   help="depth 0 (none) where the expected error is above M metres, in --out and --ply")
    c.add_argument("--fill-all", action="store_true",
                   help="write the dense map, depth also where no sample supports it (default: 0 there)")
    c.add_argument("-q", "--quiet", action="store_true", help="no progress bar, model choice or summary")
    c.set_defaults(func=_cmd_complete)
    _add_project_parser(sub)

    e = sub.add_parser("evaluate", help="metrics of model(s) on the synthetic test split, your folder or a training "
                       "data source (Markdown table)")
    e.add_argument("--model", "--method", dest="model", action="append", default=None,
                   help="shipped model, saved model path, or a classical fill (nearest, linear, ip_basic, "
                        "colorization, lip-wavelet); repeat to compare (default: the default model of the input)")
    e.add_argument("--iterations", type=console.positive_int, default=None, metavar="K")
    data = e.add_mutually_exclusive_group()
    data.add_argument("--data", default="synthetic-indoor",
                      help="synthetic-indoor | synthetic-outdoor | FOLDER with rgb/ depth/ [sparse/] (or train/ "
                           "and val/ holding them): every frame, its own sparse/ maps as input when it has them")
    data.add_argument("--source", default=None, choices=SOURCES,
                      help="a training data source, read as training reads it; its default protocol's crop and "
                           "depth range unless --protocol says otherwise")
    e.add_argument("--root", default=None, metavar="DIR",
                   help="the folder of the --source data set (--source rendered: DIR[,DIR...], renders of one kind)")
    e.add_argument("--raw-root", default=None, metavar="DIR", help="KITTI raw drives, for --source kitti_dc")
    e.add_argument("--split", default=None, choices=("train", "val", "test"),
                   help="synthetic split (default test); FOLDER: train or val as lipjax train splits it (default: "
                        "every frame); with --source train or val (default val); --source rendered takes none")
    e.add_argument("--kind", default=None, choices=("indoor", "outdoor"),
                   help="the scenes of --source synthetic (default indoor); its depth range follows")
    e.add_argument("--size", type=console.positive_int, nargs=2, default=None, metavar=("H", "W"),
                   help="synthetic render size (default 256 320)")
    e.add_argument("--sampler", default=None,
                   help="sparse input spec, e.g. uniform:200, bernoulli:500, lidar:hdl64, or input[:N], the "
                        "data's own sparse input (a FOLDER's sparse/, KITTI's scan). Default: input for a FOLDER "
                        "with sparse/, else uniform:200")
    e.add_argument("--protocol", default=None, choices=sorted(protocols.PROTOCOLS) + [NO_PROTOCOL],
                   help="named crop/resize + depth range applied to each frame; none: frames as they are (with "
                        "--source, still the source's depth range)")
    e.add_argument("--depth-scale", type=_depth_scale, default=None, metavar="S",
                   help="for PNG ground truth in FOLDER (or --source folder)")
    intr = e.add_mutually_exclusive_group()
    intr.add_argument("--intrinsics", type=float, nargs=4, metavar=("FX", "FY", "CX", "CY"))
    intr.add_argument("--intrinsics-file", default=None, metavar="F")
    e.add_argument("--min-depth-m", type=float, default=None)
    e.add_argument("--max-depth-m", type=float, default=None, help="default: the protocol's (10 indoor, 80 outdoor)")
    e.add_argument("--limit", type=console.positive_int, default=None, metavar="N",
                   help="evaluate the first N frames only")
    e.add_argument("--seed", type=int, default=0, help="sampler seed")
    e.add_argument("--columns", default=None,
                   help=f"comma-separated metric names (default: {','.join(DEFAULT_COLUMNS)})")
    e.add_argument("--json", default=None, metavar="FILE", help="also write all results as JSON")
    e.add_argument("--quiet", action="store_true")
    e.set_defaults(func=_cmd_evaluate)

    x = sub.add_parser("export", help="export a model as StableHLO (jax.export) for a fixed input shape")
    x.add_argument("--model", default=None)
    x.add_argument("--iterations", type=console.positive_int, default=None, metavar="K")
    x.add_argument("--height", type=console.positive_int, required=True)
    x.add_argument("--width", type=console.positive_int, required=True)
    x.add_argument("--batch", type=console.positive_int, default=1)
    x.add_argument("--platforms", default=None, help="comma-separated, e.g. cpu,cuda (default: this machine's)")
    x.add_argument("--out", required=True, metavar="FILE.stablehlo")
    x.add_argument("--quiet", action="store_true")
    x.set_defaults(func=_cmd_export)

    m = sub.add_parser("models", help="list the shipped models")
    m.set_defaults(func=_cmd_models)
    d = sub.add_parser("data", help="data sets: `lipjax data render` writes the synthetic scenes to disk")
    r = d.add_subparsers(dest="data_command", required=True, metavar="ACTION").add_parser(
        "render", help="render synthetic frames into shard files, in worker processes")
    r.add_argument("--kind", required=True, choices=("indoor", "outdoor"))
    r.add_argument("--split", default="train", choices=("train", "val", "test"))
    r.add_argument("--count", type=console.positive_int, required=True, help="frames 0 .. N-1 of the split")
    r.add_argument("--out", required=True, help="folder; re-running the same command finishes an interrupted render")
    r.add_argument("--height", type=console.positive_int, default=None,
                   help="full frame (default 256x320 indoor, 128x416 outdoor)")
    r.add_argument("--width", type=console.positive_int, default=None)
    r.add_argument("--window", type=console.positive_int, nargs=2, default=None, metavar=("H", "W"),
                   help="store one HxW window per frame, rendered directly at the training crop size")
    r.add_argument("--workers", type=console.positive_int, default=None, help="processes (default: every core)")
    r.add_argument("--quiet", action="store_true")
    r.set_defaults(func=_cmd_data_render)

    t = sub.add_parser("train", help="fine-tune a model on your folder of RGB-D frames")
    t.add_argument("--data", required=True,
                   help="folder with rgb/ depth/ [sparse/] [intrinsics.txt, for a simulated LiDAR only], or train/ and "
                        "val/ holding them")
    t.add_argument("--out", required=True, help="model path stem to export to, also the run's name (then: lipjax "
                   "complete --model OUT)")
    t.add_argument("--depth-scale", type=_depth_scale, default=None, metavar="S", help="PNG depth value per metre")
    t.add_argument("--init", default=None, help="model to start from: shipped name or saved path (default: the "
                   "default model of the frames' scene, as lipjax complete picks it)")
    t.add_argument("--steps", type=console.positive_int, default=None, help="training steps (default 2000)")
    t.add_argument("--batch-size", type=console.positive_int, default=8)
    t.add_argument("--sampler", default=None, help="sparse input spec (default: 200 / 500 uniform and 200 Bernoulli "
                   "points), or input[:N] for your sparse/ maps")
    t.add_argument("--crop", type=console.positive_int, nargs=2, default=None, metavar=("H", "W"),
                   help="default 128 160")
    t.add_argument("--workers", type=int, default=2, help="loader worker processes (0: none)")
    t.add_argument("--workdir", default=None, help="checkpoints and logs (default runs/train-<--out name>)")
    t.add_argument("--quiet", action="store_true")
    t.set_defaults(func=_cmd_train)
    return parser


def _run(argv: list[str]) -> int:
    args = build_parser().parse_args(argv)
    try:
        from lipjax.utils import enable_compilation_cache

        enable_compilation_cache()
    except OSError as exc:
        _warn(f"no persistent compilation cache ({exc}); every run compiles from scratch")
    return args.func(args)


def main(argv: list[str] | None = None) -> int:
    """Runs the command line; returns the exit status (0 ok, 1 user error, 2 usage error; lipjax.console)."""
    return console.run_main(PROG, _run, list(sys.argv[1:] if argv is None else argv))


if __name__ == "__main__":
    sys.exit(main())
