"""lipjax: depth completion of your own frames (an RGB image and sparse depth or a LiDAR sweep), evaluation,
fine-tuning and export. Depth is in metres; 0 means no depth.

    lipjax complete --rgb IMG --depth SPARSE [--depth-scale S] [--model NAME|PATH] [--iterations K] --out OUT
                    [--max-side N] [--ply FILE (--intrinsics fx fy cx cy | --intrinsics-file F)] [--threads N]
                    [--uncertainty FILE] [--max-uncertainty M] [--fill-all | --blank-unsupported]
                    [--[no-]flip] [--no-cross-check] [--explain: print each frame's plan, write nothing]
    lipjax complete --rgb IMG --lidar SWEEP --calib FILE [--camera 2] --out OUT ...   (the sweep projected first)
    lipjax project --rgb IMG --lidar SWEEP --calib FILE [--camera 2] --out SPARSE.npy|.png   (the sparse input only)
    lipjax evaluate [--model NAME|PATH ...] [--data synthetic-indoor|synthetic-outdoor|FOLDER] [--sampler SPEC]
    lipjax evaluate [--model NAME|PATH ...] --source NAME --root DIR [--raw-root DIR] [--split val] (as training reads)
    lipjax evaluate [--model NAME|PATH ...] --source synthetic [--kind indoor|outdoor] [--split val]
    lipjax export [--model M] --height H --width W [--batch B] [--samples N] [--scattered] [--[no-]flip] --out F
    lipjax train --data FOLDER --out MODEL [--depth-scale S] [--steps N] [--keep best|last] [--self-supervised]
    lipjax data render --kind indoor|outdoor --split train --count N --out DIR [--workers W]
    lipjax models | lipjax --version

Run `lipjax COMMAND --help` for a command's options.
"""
from __future__ import annotations

import argparse
import functools
import sys

from lipjax import __version__, console
from lipjax.cli_help import (CLASSICAL, COMPLETE_HELP, DEFAULT_COLUMNS, NO_PROTOCOL, OUT_FORMATS, PROTOCOLS, SOURCES,
                             SPLITS, SYNTHETIC_KINDS, TRAIN_STEPS_HELP, TRAINING, depth_scale)

PROG = "lipjax"
_RAW, _BOOL = argparse.RawDescriptionHelpFormatter, argparse.BooleanOptionalAction


def _cmd_complete(args) -> int:
    from lipjax import files, utils
    if args.threads:
        utils.limit_cpu_threads(args.threads)
    frames = {k: getattr(args, k) for k in ("lidar", "calib", "camera", "depth_scale", "model", "iterations",
                                            "max_side", "cross_check", "flip")}  # what the plan of a frame needs
    if args.explain:
        print(files.explain_files(args.rgb, args.depth, **frames).summary())
        return 0
    done = files.complete_files(
        args.rgb, args.depth, args.out, intrinsics=args.intrinsics or args.intrinsics_file, progress=not args.quiet,
        log=None if args.quiet else console.say, workers=min(args.threads or files.READ_WORKERS, files.READ_WORKERS),
        **frames, **{k: getattr(args, k) for k in ("out_format", "color_range", "ply", "uncertainty",
                                                   "max_uncertainty", "fill_all", "blank_unsupported")})
    if not args.quiet:
        console.say(done.summary())
    return 0


def _cmd_project(args) -> int:
    from lipjax.files import project_file
    done = project_file(args.rgb, args.lidar, args.calib, args.out, camera=args.camera, depth_scale=args.depth_scale)
    if not args.quiet:
        console.say(done.summary())
    return 0


def _cmd_evaluate(args) -> int:
    from lipjax.evaluate import evaluate_methods, markdown_table, save_json
    columns = tuple(c.strip() for c in args.columns.split(",")) if args.columns else DEFAULT_COLUMNS
    report = evaluate_methods(
        args.model, progress=not args.quiet, intrinsics=args.intrinsics or args.intrinsics_file,
        **{k: getattr(args, k) for k in ("iterations", "min_depth_m", "max_depth_m", "limit", "seed", "data", "source",
                                         "root", "raw_root", "split", "kind", "size", "sampler", "protocol",
                                         "depth_scale", "working_size")})
    print(report.header() + "\n\n" + markdown_table(report.results, columns=columns))
    if args.json:
        save_json(report.results, args.json)
    return 0


def _cmd_export(args) -> int:
    from lipjax.export import export
    platforms = tuple(p.strip() for p in args.platforms.split(",")) if args.platforms else None
    try:
        written = export(args.model, args.out, iterations=args.iterations, platforms=platforms, **{
            k: getattr(args, k) for k in ("height", "width", "batch", "samples", "scattered", "flip")})
    except ImportError as exc:  # the optional flatbuffers / onnx packages
        raise console.UserError(str(exc)) from exc
    if not args.quiet:
        console.say(written.summary())
    return 0


def _cmd_data_render(args) -> int:
    from lipjax.data.rendered import render_to_disk
    try:
        out = render_to_disk(args.kind, args.split, args.count, args.out, height=args.height, width=args.width,
                             window=args.window, workers=args.workers, progress=not args.quiet)
    except (KeyboardInterrupt, SystemExit) as stop:  # Ctrl-C, SIGTERM: the workers are stopped already
        console.say(f"{PROG}: render stopped; its finished shards stay in {args.out}, "
                    "and the same command finishes it")
        return 130 if isinstance(stop, KeyboardInterrupt) else stop.code
    print(f"rendered {args.count} {args.kind}/{args.split} frames to {out}")
    return 0


def _cmd_train(args) -> int:
    from lipjax.train.adapt import adapt_folder
    from lipjax.train.run import fine_tune_folder
    hide = args.self_supervised  # None: fine-tune on depth/; a share: adapt by self-supervision
    train = fine_tune_folder if hide is None else functools.partial(adapt_folder, hide=hide)
    train(args.data, args.out, init=args.init, steps=args.steps, batch_size=args.batch_size,
          workdir=args.workdir, progress=not args.quiet, log=None if args.quiet else console.say,
          depth_scale=args.depth_scale, num_workers=args.workers, crop=args.crop and tuple(args.crop),
          train_sampler=args.sampler, keep=args.keep)
    return 0


def _cmd_models(args) -> int:
    from lipjax.methods import listing
    print(listing())
    return 0


def _add_model_args(p, help_text: str | None = None) -> None:
    p.add_argument("--model", help=help_text)
    p.add_argument("--iterations", type=console.positive_int, metavar="K", help="run the first K ADMM iterations")


def _add_intrinsics_args(p, help_values: str | None = None, help_file: str | None = None) -> None:
    group = p.add_mutually_exclusive_group()
    group.add_argument("--intrinsics", type=float, nargs=4, metavar=("FX", "FY", "CX", "CY"), help=help_values)
    group.add_argument("--intrinsics-file", metavar="F", help=help_file)


def _add_lidar_args(p, required: bool) -> None:
    """--lidar, --calib, --camera: of `project`, and of `complete` as the alternative to --depth."""
    p.add_argument("--lidar", required=required, metavar="SWEEP",
                   help="LiDAR sweep: KITTI .bin, .npy (N, >=3) x y z metres, or .pcd")
    p.add_argument("--calib", required=required, metavar="FILE", help="KITTI object calib .txt, KITTI raw date "
                   "folder, KITTI odometry calib.txt, or a rig .txt/.yaml with K and T_cam_from_lidar")
    p.add_argument("--camera", type=int, default=2, metavar="N", help="KITTI camera of --rgb: 2 (image_2) or 3")


def _add_complete_parser(sub) -> None:
    c = sub.add_parser("complete", help="complete sparse depth of your own frames", formatter_class=_RAW,
                       description=COMPLETE_HELP)
    c.add_argument("--rgb", required=True, help="colour image (.png/.jpg) or a folder of them")
    c.add_argument("--depth", help="sparse depth: 16-bit .png (needs --depth-scale) or .npy metres; or a folder")
    _add_lidar_args(c, required=False)
    c.add_argument("--depth-scale", type=depth_scale, metavar="S", help="PNG value per metre: 256 (kitti), "
                   "1000 (nyu), 5000 (tum); required by .png input (no default); .png output: 256 when not given")
    _add_model_args(c, f"shipped model (lipjax models), saved model path or classical fill ({', '.join(CLASSICAL)})")
    out = c.add_mutually_exclusive_group(required=True)  # where to write, or --explain: the plan alone
    out.add_argument("--out", help="X.npy | X.png | X.color.png, or a folder with folder inputs")
    c.add_argument("--out-format", choices=OUT_FORMATS, help="per-frame format with folder inputs")
    c.add_argument("--max-side", type=console.positive_int, metavar="N", help="run downsized to this longer side")
    c.add_argument("--color-range", type=float, nargs=2, metavar=("MIN_M", "MAX_M"), help="metres of .color.png's map")
    c.add_argument("--ply", help="also write a coloured point cloud (.ply; a folder with folder inputs)")
    _add_intrinsics_args(c, "pixels, of the RGB image", '"fx fy cx cy", the 9 numbers of K, or a calibration file')
    c.add_argument("--uncertainty", metavar="FILE", help="also write the expected absolute error (above)")
    c.add_argument("--max-uncertainty", type=float, metavar="M", help="depth 0 where the expected error > M metres")
    where = c.add_mutually_exclusive_group()  # neither: what the model or method returns, as lipjax.complete
    where.add_argument("--fill-all", action="store_true", help="depth at every pixel (0s a method leaves: nearest)")
    where.add_argument("--blank-unsupported", action="store_true", help="0 where no sample supports the depth")
    c.add_argument("--flip", action=_BOOL, help="learned models: average in the flipped frame (default: scan lines)")
    c.add_argument("--no-cross-check", dest="cross_check", action="store_false", help="no linear-fill check")
    out.add_argument("--explain", action="store_true", help="print each frame's plan; run and write nothing (above)")
    c.add_argument("--threads", type=console.positive_int, metavar="N", help="run on N CPU cores (default: every one)")
    c.add_argument("-q", "--quiet", action="store_true", help="no progress bar, model choice or summary")
    c.set_defaults(func=_cmd_complete)


def _add_project_parser(sub) -> None:
    p = sub.add_parser("project", help="project a LiDAR sweep into a camera image: the sparse depth input",
                       description="Projects a LiDAR sweep into the camera of --rgb (the nearest point per pixel; "
                                   "depth = z in the camera frame, metres) and writes the sparse depth image.")
    _add_lidar_args(p, required=True)
    p.add_argument("--rgb", required=True, help="the camera's image (gives the size)")
    p.add_argument("--out", required=True,
                   help="SPARSE.npy (float32 metres) | .png (16-bit, value = metres * --depth-scale) | .color.png")
    p.add_argument("--depth-scale", type=depth_scale, metavar="S", help="PNG value per metre of .png (default 256)")
    p.add_argument("-q", "--quiet", action="store_true", help="no summary line")
    p.set_defaults(func=_cmd_project)


def _add_evaluate_parser(sub) -> None:
    e = sub.add_parser("evaluate", help="metrics of model(s) on the synthetic test split, your folder or a training "
                       "data source (Markdown table)")
    e.add_argument("--model", "--method", dest="model", action="append", help=f"shipped model, saved model path, or "
                   f"a classical fill ({', '.join(CLASSICAL)}); repeat to compare (default: the default model)")
    e.add_argument("--iterations", type=console.positive_int, metavar="K")
    data = e.add_mutually_exclusive_group()
    data.add_argument("--data", help="synthetic-indoor (default) | synthetic-outdoor | FOLDER with rgb/ depth/ "
                      "[sparse/] (or train/ and val/ holding them): every frame, its sparse/ maps as input if any")
    data.add_argument("--source", choices=SOURCES, help="a training data source, read as training reads it; its "
                      "default protocol's crop and depth range unless --protocol says otherwise")
    e.add_argument("--root", metavar="DIR", help="the --source data set's folder (rendered: DIR[,DIR...], one kind)")
    e.add_argument("--raw-root", metavar="DIR", help="KITTI raw drives, for --source kitti_dc")
    e.add_argument("--split", choices=SPLITS, help="synthetic split (default test); FOLDER: "
                   "train or val as lipjax train splits it (default: every frame); --source: train|val (default val)")
    e.add_argument("--kind", choices=SYNTHETIC_KINDS, help="the scenes of --source synthetic (default indoor)")
    e.add_argument("--size", type=console.positive_int, nargs=2, metavar=("H", "W"), help="synthetic: default 256 320")
    e.add_argument("--sampler", help="sparse input spec, e.g. uniform:200, bernoulli:500, lidar:hdl64, or input[:N], "
                   "the data's own sparse input (a FOLDER's sparse/, KITTI's scan). Default: input for a FOLDER with "
                   "sparse/, else uniform:200")
    e.add_argument("--protocol", choices=sorted(PROTOCOLS) + [NO_PROTOCOL], help="named crop/resize + depth range "
                   "applied to each frame; none: frames as they are (with --source, still the source's depth range)")
    e.add_argument("--depth-scale", type=depth_scale, metavar="S", help="PNG depth value per metre in FOLDER")
    _add_intrinsics_args(e)
    e.add_argument("--working-size", action="store_true", help="score models as `lipjax complete` runs them: at "
                   "the samples' working size, measured pixels set back (default: at the input's size, as the tables)")
    e.add_argument("--min-depth-m", type=float)
    e.add_argument("--max-depth-m", type=float,
                   help="default: the protocol's (10 indoor, 80 outdoor); FOLDER: required unless --protocol")
    e.add_argument("--limit", type=console.positive_int, metavar="N", help="evaluate the first N frames only")
    e.add_argument("--seed", type=int, default=0, help="sampler seed")
    e.add_argument("--columns", help=f"comma-separated metric names (default: {','.join(DEFAULT_COLUMNS)})")
    e.add_argument("--json", metavar="FILE", help="also write all results as JSON")
    e.add_argument("-q", "--quiet", action="store_true", help="no progress bar")
    e.set_defaults(func=_cmd_evaluate)


def _add_export_parser(sub) -> None:
    x = sub.add_parser("export", help="export a model as ONNX (onnxruntime) or StableHLO (jax) for one input shape")
    _add_model_args(x)
    x.add_argument("--height", type=console.positive_int, required=True)
    x.add_argument("--width", type=console.positive_int, required=True)
    x.add_argument("--batch", type=console.positive_int, default=1)
    x.add_argument("--samples", type=console.positive_int, help=".onnx: samples per frame (sets the working size)")
    x.add_argument("--scattered", action="store_true", help=".onnx: scattered points, not LiDAR scan lines")
    x.add_argument("--flip", action=_BOOL, help=".onnx: as lipjax complete's, in the graph (default: scan lines)")
    x.add_argument("--platforms", help=".stablehlo: comma-separated, e.g. cpu,cuda (default: this machine's)")
    x.add_argument("--out", required=True, metavar="FILE", help="FILE.onnx (onnxruntime) or FILE.stablehlo (jax)")
    x.add_argument("-q", "--quiet", action="store_true", help="no summary line")
    x.set_defaults(func=_cmd_export)


def _add_data_parser(sub) -> None:
    d = sub.add_parser("data", help="data sets: `lipjax data render` writes the synthetic scenes to disk")
    r = d.add_subparsers(dest="data_command", required=True, metavar="ACTION").add_parser(
        "render", help="render synthetic frames into shard files, in worker processes")
    r.add_argument("--kind", required=True, choices=SYNTHETIC_KINDS)
    r.add_argument("--split", default="train", choices=SPLITS)
    r.add_argument("--count", type=console.positive_int, required=True, help="frames 0 .. N-1 of the split")
    r.add_argument("--out", required=True, help="folder; re-running the same command finishes an interrupted render")
    r.add_argument("--height", type=console.positive_int, help="full frame (default 256x320 indoor, 128x416 outdoor)")
    r.add_argument("--width", type=console.positive_int)
    r.add_argument("--window", type=console.positive_int, nargs=2, metavar=("H", "W"), help="one HxW window a frame")
    r.add_argument("--workers", type=console.positive_int, help="processes (default: every core)")
    r.add_argument("-q", "--quiet", action="store_true", help="no progress bar")
    r.set_defaults(func=_cmd_data_render)


def _add_train_parser(sub) -> None:
    t = sub.add_parser("train", help="fine-tune a model on your folder of RGB-D frames")
    t.add_argument("--data", required=True, help="folder with rgb/ depth/ [sparse/] [intrinsics.txt, for a simulated "
                   "LiDAR only], or train/ and val/ holding them")
    t.add_argument("--out", required=True, help="model path stem to export to; its name NAME is the "
                   "run's (then: lipjax complete --model OUT)")
    t.add_argument("--depth-scale", type=depth_scale, metavar="S", help="PNG depth value per metre")
    t.add_argument("--init", help="model to start from: shipped name or saved path (default: the default model)")
    t.add_argument("--steps", type=console.positive_int, help=TRAIN_STEPS_HELP)
    t.add_argument("--batch-size", type=console.positive_int, help=f"frames per step (default {TRAINING.batch_size})")
    t.add_argument("--sampler", help="sparse input spec (default: 200 / 500 uniform and 200 Bernoulli "
                   "points), or input[:N] for your sparse/ maps")
    t.add_argument("--crop", type=console.positive_int, nargs=2, metavar=("H", "W"),
                   help=f"random training crops (default {TRAINING.crop[0]} {TRAINING.crop[1]})")
    t.add_argument("--workers", type=int, help=f"loader processes (0: none; default {TRAINING.workers})")
    t.add_argument("--self-supervised", type=float, nargs="?", const=0.2, metavar="HIDE", help="rgb/ and sparse/ "
                   "alone (no depth/): learn from a share HIDE (default 0.2) of each frame's samples hidden from it")
    t.add_argument("--keep", choices=("best", "last"), default="best", help="if the trained model validates worse "
                   "than its start: export the start (best, default) or the trained model anyway (last)")
    t.add_argument("--workdir", help="checkpoints and logs (default runs/train-NAME, self-supervised runs/adapt-NAME)")
    t.add_argument("-q", "--quiet", action="store_true", help="no progress bar or log lines")
    t.set_defaults(func=_cmd_train)


def build_parser() -> argparse.ArgumentParser:
    parser = console.ArgumentParser(prog=PROG, description=__doc__, formatter_class=_RAW)
    parser.add_argument("--version", action="version", version=f"{PROG} {__version__}")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for add in (_add_complete_parser, _add_project_parser, _add_evaluate_parser, _add_export_parser, _add_data_parser,
                _add_train_parser):
        add(sub)
    sub.add_parser("models", help="list the shipped models and hand-crafted methods").set_defaults(func=_cmd_models)
    return parser


def _run(argv: list[str]) -> int:
    args = build_parser().parse_args(argv)
    from lipjax.utils import enable_compilation_cache  # after parsing: --help loads no JAX
    try:
        enable_compilation_cache()
    except OSError as exc:
        console.warn(PROG, f"no persistent compilation cache ({exc}); every run compiles from scratch")
    return args.func(args)


def main(argv: list[str] | None = None) -> int:
    """Runs the command line; returns the exit status (0 ok, 1 user error, 2 usage error; lipjax.console)."""
    return console.run_main(PROG, _run, list(sys.argv[1:] if argv is None else argv))


if __name__ == "__main__":
    sys.exit(main())
