"""Writes docs/gallery.png: synthetic indoor and outdoor frames (RGB, depth, sparse input).

Run by hand:  python -m benchmarks.gallery [--out docs/gallery.png] [--split val] [--start 0] [--n 4]

Depth uses one fixed colour range per kind (indoor 0-10 m, outdoor 0-80 m), invalid pixels (sky, beyond
80 m) black. The sparse input is drawn with lipjax.data.sampling (indoor: 200 uniform points; outdoor: an
HDL-64-like LiDAR pattern), dilated so that single pixels are visible at print size.
"""
from __future__ import annotations

import argparse
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from lipjax.data import synthetic
from lipjax.data.sampling import sampler_from_spec
from lipjax.interfaces import SCENE_MAX_DEPTH_M

MAX_DEPTH_M = {"indoor": SCENE_MAX_DEPTH_M["indoor"], "outdoor": synthetic.RENDER_FAR_CLIP_M}


def sparse_input(frame, kind: str) -> np.ndarray:
    """(H, W) sparse depth, 0 = no point."""
    return sampler_from_spec("uniform:200" if kind == "indoor" else "lidar:hdl64")(frame)


def coloured(depth: np.ndarray, vmax: float, cmap) -> np.ndarray:
    img = cmap(np.clip(depth / vmax, 0, 1))[..., :3]
    img[depth <= 0] = 0.0
    return img


def dilate(sparse: np.ndarray, r: int = 1) -> np.ndarray:
    out = sparse.copy()
    H, W = sparse.shape
    for dy in range(-r, r + 1):
        for dx in range(-r, r + 1):
            src = sparse[max(0, -dy):H - max(0, dy), max(0, -dx):W - max(0, dx)]
            dst = out[max(0, dy):H - max(0, -dy), max(0, dx):W - max(0, -dx)]
            np.copyto(dst, src, where=(dst <= 0) & (src > 0))
    return out


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", default=os.path.join(os.path.dirname(__file__), "..", "docs", "gallery.png"))
    ap.add_argument("--split", default="val")
    ap.add_argument("--start", type=int, default=0)
    ap.add_argument("--n", type=int, default=4, help="frames per kind")
    ap.add_argument("--height", type=int, default=256)
    ap.add_argument("--width", type=int, default=320)
    args = ap.parse_args(argv)

    cmap = plt.get_cmap("turbo")
    rows = [(kind, i) for kind in synthetic.SYNTHETIC_KINDS for i in range(args.start, args.start + args.n)]
    fig, axes = plt.subplots(len(rows), 3, figsize=(3 * 3.2, len(rows) * 2.65), squeeze=False)
    for r, (kind, i) in enumerate(rows):
        s = synthetic.render(kind, args.split, i, args.height, args.width)
        sp = sparse_input(s, kind)
        vmax = MAX_DEPTH_M[kind]
        d = s.depth[s.valid]
        panels = [
            (s.rgb, f"{s.id}"),
            (coloured(s.depth, vmax, cmap), f"depth {d.min():.1f}-{d.max():.1f} m (0-{vmax:.0f} m)"),
            (coloured(dilate(sp), vmax, cmap), f"sparse input: {(sp > 0).sum()} points"),
        ]
        for c, (img, title) in enumerate(panels):
            ax = axes[r, c]
            ax.imshow(img, interpolation="nearest")
            ax.set_title(title, fontsize=7)
            ax.axis("off")
    fig.tight_layout()
    os.makedirs(os.path.dirname(os.path.abspath(args.out)), exist_ok=True)
    fig.savefig(args.out, dpi=80)
    print(f"wrote {os.path.abspath(args.out)}")


if __name__ == "__main__":
    main()
