"""Trains a model from a named config (experiments/configs/) on any data source: a thin caller of lipjax.train.

    python -m experiments.train --config lip_cnn_indoor [--workdir runs/lip_cnn_indoor] [--set g_steps=200]
    python -m experiments.train --config lip_cnn_nyu --set data.root=/data/nyudepthv2 --export runs/lip_cnn_nyu/model
    python -m experiments.train --config lip_cnn_indoor --export-only --export PATH   # the latest checkpoint
    python -m experiments.train --config lip_cnn_indoor --export-only --average 2 --export PATH  # mean of 2
    python -m experiments.train --config lip_any --soup OLDER,NEWER --export PATH  # mean of models of one chain

A killed run resumes from its last checkpoint when started again with the same workdir. The run writes only into
its workdir (checkpoints, metrics.jsonl, curves.png); the model is exported only to --export PATH.

Several hosts: the same command in every process, with --distributed (jax.distributed; on SLURM, Open MPI,
Kubernetes or Cloud TPU nothing more, elsewhere also --coordinator HOST:PORT --num-processes N --process-id I);
each process reads its slice of every batch, process 0 writes the logs, checkpoints and the export:

    python -m experiments.train --config lip_cnn_indoor --distributed --coordinator node0:1234 --num-processes 2 \
        --process-id 0 --workdir /shared/runs/lip_cnn_indoor --export /shared/models/lip-cnn   # 1 on the other
"""
from __future__ import annotations

import argparse
import sys

from lipjax.console import ArgumentParser, one_line, positive_int, run_main
from lipjax.train.config import parse_overrides
from lipjax.train.run import run, soup
from lipjax.utils import enable_compilation_cache, start_processes

PROG = "python -m experiments.train"  # how it is run (also right as a script: no __spec__)


def main(argv=None) -> None:
    p = ArgumentParser(prog=PROG, description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--config", required=True, help="a name of experiments.configs.CONFIGS")
    p.add_argument("--workdir", default=None, help="default: runs/<config>")
    p.add_argument("--set", action="append", default=[], metavar="FIELD=VALUE", help="override a config field")
    p.add_argument("--export", default=None, help="model path stem to export to (default: no export)")
    p.add_argument("--export-only", action="store_true", help="export the latest checkpoint without training")
    p.add_argument("--average", type=int, default=1, metavar="N",
                   help="export the mean parameters of the newest N checkpoints (checkpoint averaging; default 1)")
    p.add_argument("--soup", default=None, metavar="MODEL,MODEL",
                   help="export the mean parameters of saved models of one chain of warm starts, newest last "
                        "(model soup; validated on --config's validation set; trains nothing)")
    p.add_argument("--no-progress", action="store_true")
    p.add_argument("--distributed", action="store_true",
                   help="one process of a run of several (hosts): jax.distributed, the cluster read from the "
                        "environment where it can be (SLURM, Open MPI, Kubernetes, Cloud TPU)")
    p.add_argument("--coordinator", metavar="HOST:PORT", help="with --distributed: process 0's address")
    p.add_argument("--num-processes", type=positive_int, metavar="N", help="with --distributed: how many")
    p.add_argument("--process-id", type=int, metavar="I", help="with --distributed: this process, 0 to N-1")
    args = p.parse_args(argv)
    if (args.export_only or args.soup) and args.export is None:
        p.error(f"{'--soup' if args.soup else '--export-only'} needs --export PATH")
    cluster = {"coordinator": args.coordinator, "num_processes": args.num_processes, "process_id": args.process_id}
    if not args.distributed and any(v is not None for v in cluster.values()):
        p.error("--coordinator, --num-processes and --process-id need --distributed")
    if args.distributed and (args.soup or args.export_only or args.average > 1):
        p.error("--soup, --export-only and --average read saved models or checkpoints: run them without --distributed")
    if args.distributed:
        start_processes(**cluster)
    from experiments.configs import get_config

    try:
        config = get_config(args.config, parse_overrides(args.set))
    except ValueError as exc:  # an unknown config or field, or a bad value: a usage error
        p.error(one_line(exc))
    enable_compilation_cache()
    if args.soup:
        soup(config, [m.strip() for m in args.soup.split(",")], args.export)
        return
    run(config, args.workdir or f"runs/{args.config}", export=args.export, export_only=args.export_only,
        average=args.average, progress=not args.no_progress)


if __name__ == "__main__":
    sys.exit(run_main(PROG, main))
