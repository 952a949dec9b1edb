"""Inference speed of the LIP models: frames/s, GFLOP per frame, and the machine's matmul rate in the same run.

Run by hand (never a test):

    python -m benchmarks.prox_speed [--height 256] [--width 320] [--iterations 3] [--repeats 20]
                                    [--models lip-fast-indoor,...]

Rows: the paper-style prox (lipjax.priors.network "small" and "paper" presets) and the fast prox
(lipjax.priors.fast "fast"), each as a K-iteration LIP model started from the linear fill (as the shipped
indoor models), untrained weights (speed does not depend on the weights), plus any shipped/saved models named
with --models. Columns:
  GFLOP       XLA's flop count of the compiled solver for one frame (batch 1), without the host fill;
  solver ms   the jitted solver alone (inputs already on the device);
  fill ms     the host-side initial estimate (Delaunay linear fill), numpy/scipy;
  total ms    `Completer.__call__` end to end (input checks, host fill, solver, copy back): what a user waits;
  frames/s    1000 / total ms.
The first row is a 2048x2048 float32 matmul (17.2 GFLOP) timed in the same run: divide by its rate to compare
runs made on machines, or under loads, that differ; the system's 1-minute load average is printed beside it (above
the core count, other processes share the cores). Times are medians over --repeats calls after one warm-up.
"""
from __future__ import annotations

import argparse
import os

import jax
import jax.numpy as jnp
import numpy as np

from benchmarks.common import matmul_rate, median_ms
from lipjax.inference import Completer, compiled_apply, load_model
from lipjax.model import LIPConfig
from lipjax.priors.fast import PRESETS as FAST_PRESETS
from lipjax.priors.network import network_preset


def _frame(height: int, width: int, samples: int = 200):
    rng = np.random.default_rng(0)
    rgb = rng.integers(0, 256, (height, width, 3), dtype=np.uint8)
    sparse = np.zeros((height, width), np.float32)
    idx = rng.choice(height * width, samples, replace=False)
    sparse.reshape(-1)[idx] = rng.uniform(0.5, 9.5, samples)
    return rgb, sparse


def measure(completer: Completer, rgb: np.ndarray, sparse: np.ndarray, repeats: int) -> dict:
    config, params = completer.config, completer.params
    extra = config.host_inputs(sparse[None])
    run = compiled_apply(config, False)
    args = (params, jnp.asarray(rgb[None]), jnp.asarray(sparse[None]), {k: jnp.asarray(v) for k, v in extra.items()})
    compiled = run.lower(*args).compile()  # one compilation serves the flop count and the solver timing
    cost = compiled.cost_analysis()
    cost = cost[0] if isinstance(cost, (list, tuple)) else cost
    solver = median_ms(lambda: jax.block_until_ready(compiled(*args)), repeats)
    fill = median_ms(lambda: config.host_inputs(sparse[None]), repeats) if extra else 0.0
    total = median_ms(lambda: completer(rgb, sparse), repeats)
    return {"params_M": config.parameter_count(params) / 1e6, "gflop": cost.get("flops", float("nan")) / 1e9,
            "solver_ms": solver, "fill_ms": fill, "total_ms": total, "fps": 1e3 / total}


def main(argv=None) -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--height", type=int, default=256)
    p.add_argument("--width", type=int, default=320)
    p.add_argument("--iterations", type=int, default=3)
    p.add_argument("--repeats", type=int, default=20)
    p.add_argument("--models", default="", help="comma-separated shipped model names or saved model paths")
    args = p.parse_args(argv)

    rgb, sparse = _frame(args.height, args.width)
    rows = {
        f"paper-style G 'small', K={args.iterations}": network_preset("small"),
        f"paper-style G 'paper', K={args.iterations}": network_preset("paper"),
        f"the fast prox G, K={args.iterations}": FAST_PRESETS["fast"],
    }
    completers = {name: Completer.random(LIPConfig(prior=prior, num_iterations=args.iterations,
                                                   initial_estimate="linear"))
                  for name, prior in rows.items()}
    for name in filter(None, args.models.split(",")):
        completers[name] = load_model(name)

    mm_ms, mm_rate = matmul_rate(args.repeats)
    print(f"{jax.devices()[0].platform} x{os.cpu_count()} cores, {args.height}x{args.width}, batch 1; "
          f"2048x2048 matmul: {mm_ms:.1f} ms = {mm_rate:.0f} GFLOP/s; load average {os.getloadavg()[0]:.1f}\n")
    print("| model | params M | GFLOP | solver ms | fill ms | total ms | frames/s |")
    print("|---|---:|---:|---:|---:|---:|---:|")
    for name, completer in completers.items():
        r = measure(completer, rgb, sparse, args.repeats)
        print(f"| {name} | {r['params_M']:.2f} | {r['gflop']:.2f} | {r['solver_ms']:.1f} | {r['fill_ms']:.1f} | "
              f"{r['total_ms']:.1f} | {r['fps']:.1f} |", flush=True)


if __name__ == "__main__":
    main()
