"""The paper's Table I: depth completion from 200 points on NYU Depth v2 (or the embedded synthetic indoor data).

    python -m experiments.nyu_200pts                                   # NYU if found, else the synthetic split
    python -m experiments.nyu_200pts --data-dir /data/nyudepthv2       # NYU val (h5), the paper's protocol
    python -m experiments.nyu_200pts --data-dir ... --protocol ma      # Ma et al.'s 228x304 protocol
    python -m experiments.nyu_200pts --variant smoke --out /tmp/x      # a 2-image check

Writes to --out (default out/nyu_200pts): results.json (every method's aggregated metrics, units in the keys,
with data set, protocol, sampler, seed and image count), table.md, and figure.png (the paper's Fig. 3: 3 frames,
the 4 key methods, each with its error map).
Without --data-dir, NYU is looked for in $LIPJAX_NYU_DIR, then data/nyudepthv2, ~/data/nyudepthv2 and
/data/nyudepthv2 (lipjax.data.locate); when it is not there, the run uses the embedded synthetic indoor test split
and says so. Default variant: 100 frames (synthetic: 256x320), every available method; about 5 minutes on 2 CPU
cores on the synthetic split.
"""
from __future__ import annotations

import argparse
import dataclasses
import pathlib
import sys

from experiments.common import evaluate_methods, load_methods, model_columns, qualitative_figure, write_results
from lipjax.console import ArgumentParser, positive_int, run_main
from lipjax.data.locate import find_data_root, not_found_note
from lipjax.data.protocols import get_protocol
from lipjax.data.sampling import sampler_from_spec
from lipjax.data.synthetic import SyntheticDataset
from lipjax.evaluate import open_eval_source
from lipjax.methods import available_methods
from lipjax.utils import enable_compilation_cache

PROG = f"python -m {__spec__.name}"  # as run: the same when imported

COLUMNS = ("rmse_m", "rel", "delta1_pct", "delta2_pct", "delta3_pct", "mae_m", "mae_sampled_m", "ms_per_frame")


@dataclasses.dataclass(frozen=True)
class Config:
    """Table I. num_points: the paper's 200 uniformly drawn valid pixels per image (exactly N)."""

    num_points: int = 200
    limit: int | None = 100
    methods: tuple[str, ...] | None = None  # None: every method available for indoor scenes
    seed: int = 0
    figure_frames: int = 3


VARIANTS = {
    "default": Config(),
    "full": Config(limit=None),
    "smoke": Config(limit=2, methods=("nearest", "linear"), figure_frames=1),
}


def main(argv=None) -> dict:
    p = ArgumentParser(prog=PROG, description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--data-dir", help="NYU Depth v2 h5 root (nyudepthv2/{train,val}/<scene>/<n>.h5)")
    p.add_argument("--protocol", choices=("paper", "ma"), default="paper")
    p.add_argument("--variant", choices=sorted(VARIANTS), default="default")
    p.add_argument("--methods", help="comma-separated method names (default: all available)")
    p.add_argument("--limit", type=positive_int, help="evaluate only the first N frames")
    p.add_argument("--train", action="store_true", help="retrain LIP+CNN and LIP+AD first (see --train-steps)")
    p.add_argument("--train-steps", type=positive_int, default=200,
                   help="G steps for LIP+CNN and adversarial steps for LIP+AD")
    p.add_argument("--out", default="out/nyu_200pts")
    args = p.parse_args(argv)
    enable_compilation_cache()
    config = VARIANTS[args.variant]
    if args.limit is not None:
        config = dataclasses.replace(config, limit=args.limit)
    out = pathlib.Path(args.out)

    methods = args.methods.split(",") if args.methods else list(config.methods or available_methods("indoor"))
    if args.train:
        methods = _retrain(out, args.train_steps) + [m for m in methods if not m.startswith(("lip-cnn", "lip-ad"))]

    sampler_spec = f"uniform:{config.num_points}"
    data_dir = args.data_dir or find_data_root("nyu")
    if data_dir:  # the nyu_h5 source, read as training reads it
        source, protocol = open_eval_source("nyu_h5", data_dir, sampler=sampler_spec, protocol=f"nyu_{args.protocol}")
        dataset, sampler = source.dataset, source.sampler
        data_name = f"NYU Depth v2 val ({data_dir})"
        print(f"[lipjax] NYU Depth v2 from {data_dir}", flush=True)
    else:
        protocol = get_protocol("synthetic_indoor")
        dataset, sampler = SyntheticDataset("indoor", "test"), sampler_from_spec(sampler_spec)
        data_name = "embedded synthetic indoor test split (lipjax.data.synthetic)"
        print(f"[lipjax] NYU Depth v2 not found ({not_found_note('nyu')}), so this runs on the embedded synthetic "
              "indoor test split (256x320).", flush=True)
    completers = load_methods(methods)
    results = evaluate_methods(completers, dataset, sampler, min_depth_m=protocol.min_depth_m,
                               max_depth_m=protocol.max_depth_m, limit=config.limit, seed=config.seed)
    meta = {
        "title": f"Table I: {config.num_points} points, {data_name}",
        "description": f"protocol {protocol.name}; sampler uniform:{config.num_points} (exactly N valid pixels, keyed "
                       f"by frame id, seed {config.seed}); {next(iter(results.values())).num_images} images; metrics "
                       f"per image over valid GT in [{protocol.min_depth_m}, {protocol.max_depth_m}] m, then "
                       "averaged; params in M; train_images: the images a learned model was trained on.",
        "dataset": data_name, "protocol": protocol.name, "sampler": f"uniform:{config.num_points}",
        "seed": config.seed, "num_images": next(iter(results.values())).num_images, "variant": args.variant,
    }
    table = write_results(out, results, meta, COLUMNS, model_columns(completers))
    frames = [dataset[i] for i in range(min(config.figure_frames, len(dataset)))]
    qualitative_figure(out / "figure.png", frames, [sampler(s, config.seed) for s in frames], completers, results,
                       max_depth_m=protocol.max_depth_m, max_error_m=0.5,
                       sparse_title=f"input ({config.num_points} points)")
    print(table)
    print(f"[lipjax] wrote {out}/results.json, table.md, figure.png")
    return {name: r.metrics for name, r in results.items()}


def _retrain(out: pathlib.Path, steps: int) -> list[str]:
    """Retrains LIP+CNN then LIP+AD (indoor) for `steps` steps each; returns the paths of the new models."""
    from experiments import train

    cnn, ad = out / "models/lip-cnn-indoor", out / "models/lip-ad-indoor"
    train.main(["--config", "lip_cnn_indoor", "--workdir", str(out / "runs/lip_cnn_indoor"),
                "--set", f"g_steps={steps}", "--export", str(cnn)])
    train.main(["--config", "lip_ad_indoor", "--workdir", str(out / "runs/lip_ad_indoor"), "--set", f"init_from={cnn}",
                "--set", f"d_steps={max(1, steps // 5)}", "--set", f"adv_steps={steps}", "--export", str(ad)])
    return [str(cnn), str(ad)]


if __name__ == "__main__":
    sys.exit(run_main(PROG, main))
