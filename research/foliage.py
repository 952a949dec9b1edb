"""Does a model do worse on streets whose trees are porous?

    python -m research.foliage [--model NAME] [--frames 8] [--min-changed 0.02]

Renders test streets at 352x1216 twice, with the trees and bushes as built (solid spheres) and porous
(lipjax.data.synthetic.foliage.porous_foliage, drawn by `foliage_rng("test", i)`), keeps the first `--frames`
streets (index order) where the porous version changes the depth of at least `--min-changed` of the pixels, draws
the HDL-64 pattern (seed 0) on each, and prints the model's RMSE ratio to the Delaunay linear fill on both (the
default path at its working size, without the cross-check, as model suites are compared), per frame and as
geometric means. Its result: docs/decisions/0011-porous-foliage-in-training-streets.md.
"""
from __future__ import annotations

import argparse

import numpy as np

from benchmarks.common import geometric_mean, ratio_to_linear
from lipjax.data.synthetic.dataset import foliage_rng, render_with_info
from lipjax.methods import get_completer

SIZE = (352, 1216)
PATTERN = "lidar:hdl64"


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--model", default="lip-any", help="a model name or path")
    ap.add_argument("--frames", type=int, default=8, help="streets with visible foliage to score")
    ap.add_argument("--min-changed", type=float, default=0.02, help="share of pixels whose depth porous foliage moves")
    ap.add_argument("--max-index", type=int, default=200, help="test streets to look through at most")
    args = ap.parse_args(argv)

    linear = get_completer("linear")
    solid_r, porous_r = [], []
    for i in range(args.max_index):
        solid, _ = render_with_info("outdoor", "test", i, *SIZE)
        porous, _ = render_with_info("outdoor", "test", i, *SIZE, foliage=foliage_rng("test", i))
        changed = float(np.mean(np.abs(porous.depth - solid.depth) > 1e-3))
        if changed < args.min_changed:
            continue
        a = ratio_to_linear(args.model, linear, solid, PATTERN, cross_check=False)
        b = ratio_to_linear(args.model, linear, porous, PATTERN, cross_check=False)
        solid_r.append(a), porous_r.append(b)
        print(f"street {i:3d}: depth changed on {100 * changed:4.1f} % of pixels; ratio to linear solid {a:.3f} "
              f"porous {b:.3f}", flush=True)
        if len(solid_r) == args.frames:
            break
    gs, gp = geometric_mean(solid_r), geometric_mean(porous_r)
    print(f"\n{len(solid_r)} streets, {args.model}: geometric-mean ratio to linear solid {gs:.4f}, porous {gp:.4f} "
          f"({100 * (gp / gs - 1):+.1f} %)")


if __name__ == "__main__":
    main()
