"""How much could any image be worth to the prox on real rooms? An image drawn from the ground truth, as a ceiling.

Run by hand (never a test; the shared frames are read from ../shared/realdata, never copied):

    python benchmarks/image_ceiling.py [--model NAME] [--synthetic 8] [--realdata ../shared/realdata] [--json OUT]

On the renders the photograph is worth about 16 % to the default model (RMSE with a grey image / with the
photograph), on the shared real frames about 1 % (docs/design-notes.md). Either the prox cannot read photographs,
or a real room gives the image less to add. This feeds the same 200 samples with four images and gives each RMSE
ratio to the Delaunay linear fill, default path at native size (`complete_frame`):

    photograph   the frame's own image
    grey         uniform grey (GREY): the depth-only part of the prior
    regions      an image made from the ground truth, the renders' cleanest cue: the connected regions between
                 depth edges (|d log D| > DEPTH_EDGE per pixel along x or y, on the ground truth with its holes
                 filled by the nearest valid pixel), each a flat random colour; edge pixels take the nearest region;
                 the geometric mean over REGION_DRAWS draws of the colours (one draw's ratio moves by up to ~0.15)
    flattened    the photograph after mean-shift filtering (MEAN_SHIFT_SP / _SR): texture gone, strong edges kept

Frames: the 12 shared indoor frames (NYU v2 3, Middlebury 1, lingbot 8; 200 uniform points as
benchmarks/real_frames.py draws them) and `--synthetic N` test renders of rooms at 480x640. "regions" is what the
renders teach the prox to expect of an image, handed over exactly on a real frame: if it is worth little there too,
the real frames' loss lies on the depth side of the prior, and no image realism can close it.
"""
from __future__ import annotations

import argparse
import json
import os
import sys
import zlib

import cv2
import numpy as np
from scipy import ndimage

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from benchmarks.edge_statistics import DEPTH_EDGE  # noqa: E402
from benchmarks.real_frames import GREY, INDOOR_POINTS, frames_and_inputs, rmse  # noqa: E402
from lipjax.data.sampling import UniformSampler  # noqa: E402
from lipjax.data.synthetic import SyntheticDataset  # noqa: E402
from lipjax.inference import complete_frame  # noqa: E402
from lipjax.methods import get_completer  # noqa: E402

MEAN_SHIFT_SP, MEAN_SHIFT_SR = 12, 24  # cv2.pyrMeanShiftFiltering's spatial (px) and colour (0-255) windows
REGION_DRAWS = 3  # colourings of the regions image per frame
VARIANTS = ("photograph", "grey", "regions", "flattened")


def _nearest_valid(a: np.ndarray, missing: np.ndarray) -> np.ndarray:
    idx = ndimage.distance_transform_edt(missing, return_distances=False, return_indices=True)
    return a[tuple(idx)]


def regions_image(depth: np.ndarray, valid: np.ndarray, seed: int) -> np.ndarray:
    """(H, W, 3) uint8: the ground truth's regions between depth edges, one flat random colour each."""
    ok = valid & (depth > 0)
    log_d = np.log(_nearest_valid(np.where(ok, depth, 1.0), ~ok))
    edge = np.zeros(depth.shape, bool)
    edge[:, :-1] |= np.abs(np.diff(log_d, axis=1)) > DEPTH_EDGE
    edge[:-1, :] |= np.abs(np.diff(log_d, axis=0)) > DEPTH_EDGE
    n, labels = cv2.connectedComponents((~edge).astype(np.uint8), connectivity=4)
    colours = np.random.default_rng(seed).integers(30, 230, (n, 3)).astype(np.uint8)
    return colours[_nearest_valid(labels, edge)]


def geomean(r) -> float:
    return float(np.exp(np.log(np.asarray(r)).mean()))


def variant_ratios(completer, sample, sparse, reference: float) -> dict[str, float]:
    """RMSE ratio to `reference` (linear's RMSE) of the model fed each variant's image."""
    def ratio(rgb):
        return rmse(complete_frame(completer, rgb, sparse), sample, sparse) / reference

    seed = zlib.crc32(sample.id.encode())
    flattened = cv2.pyrMeanShiftFiltering(np.ascontiguousarray(sample.rgb), MEAN_SHIFT_SP, MEAN_SHIFT_SR)
    regions = [regions_image(sample.depth, sample.valid, seed + k) for k in range(REGION_DRAWS)]
    return {"photograph": ratio(sample.rgb), "grey": ratio(np.full_like(sample.rgb, GREY)),
            "regions": geomean([ratio(rgb) for rgb in regions]), "flattened": ratio(flattened)}


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--model", default=None, help="a model name or path (default: the default path's choice)")
    ap.add_argument("--synthetic", type=int, default=8, help="test renders of rooms (480x640)")
    ap.add_argument("--realdata", default=os.path.join(os.path.dirname(__file__), "..", "..", "shared", "realdata"))
    ap.add_argument("--json", default=None)
    args = ap.parse_args(argv)
    frames = [("real", s, sparse) for group, s, sparse, _ in frames_and_inputs(os.path.abspath(args.realdata))
              if group == "indoor"]
    renders = SyntheticDataset("indoor", "test", size=args.synthetic, height=480, width=640)
    frames += [("renders", s, UniformSampler(INDOOR_POINTS)(s, 0)) for s in renders]
    linear, rows = get_completer("linear"), []
    for group, sample, sparse in frames:
        completer = get_completer(args.model, sparse=sparse)
        reference = rmse(linear(sample.rgb, sparse), sample, sparse)
        row = {"group": group, "frame": sample.id, **variant_ratios(completer, sample, sparse, reference)}
        rows.append(row)
        print(f"{sample.id:34s} " + "  ".join(f"{v} {row[v]:.3f}" for v in VARIANTS), flush=True)
    print("\n| frames | n | " + " | ".join(VARIANTS) + " | worth: photograph | worth: regions |")
    print("|---|---:|" + "---:|" * (len(VARIANTS) + 2))
    for group in ("real", "renders"):
        g = {v: geomean([r[v] for r in rows if r["group"] == group]) for v in VARIANTS}
        n = sum(r["group"] == group for r in rows)
        print(f"| {group} | {n} | " + " | ".join(f"{g[v]:.3f}" for v in VARIANTS)
              + f" | {g['grey'] / g['photograph']:.3f} | {g['grey'] / g['regions']:.3f} |")
    if args.json:
        with open(args.json, "w") as f:
            json.dump(rows, f, indent=1)
        print(f"\nwrote {args.json}")


if __name__ == "__main__":
    main()
