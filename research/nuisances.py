"""What in a photograph could make the image worthless to the prox? Photographs' nuisances put on the renders.

The model's own estimate is scored (`cross_check=False`): the default path's check against the linear fill
(lipjax.crosscheck) would mix that fill into what is measured here.

    python -m research.nuisances [--model PATH] [--frames 8]

On the shared real frames the default model given a grey image does as well as with the photograph, while on the
renders the image is worth 16-54 % (research/README.md, edge_statistics). This puts one nuisance at a time on
test-split renders (never trained on), each frame at full size through the default path
(`lipjax.inference.complete_frame`), and gives the RMSE ratio to the Delaunay linear fill with the image and with a
uniform grey one; their quotient is the image's worth (grey / image: above 1, the image helps). A nuisance that
takes the worth to about 1 on the renders is a candidate cause; one that leaves it is not.

    RGB shifted by 2 / 4 px    the photograph misregistered against the depth sensor (calibration, rolling
                               shutter, time offsets): every colour edge beside its depth edge
    depth noise 1 % / 3 %      independent per-pixel noise on the depth map, so on the samples and the ground truth
                               alike (a consumer camera's depth, KITTI's accumulated scans)
    depth wobble 2 %           a smooth relative error over the frame (structured-light distortion)
    relit                      a smooth gain field on the image (`lipjax.data.augment.relight`, strength 0.7)
    camera noise               2 % Gaussian noise and a JPEG round trip at quality 30-95 (`camera_noise`)
    texture, 3 patches         colour patterns without depth on 3 rectangles (`paint_texture`, strength 0.7)
    floor reflections          the frame rendered again with a polished floor / wet road (the scene mirrored in
                               it, lipjax.data.synthetic.renderer.Reflection, strength 0.05-0.3, blur 0.5-2 px):
                               colour structure on one plane, as tiles, polished wood and wet asphalt show it
    no depth at edges          no valid depth at failure_look's "depth edge" pixels (within 3 px of a log-depth
                               step over 0.05 per pixel), as a structured-light or stereo camera loses it: neither
                               samples nor ground truth there, where the image helps most on the renders

Rooms at 480x640 with 200 uniform points, streets at 352x1216 with the HDL-64 pattern; samples drawn with seed 0
after the nuisance; every nuisance's draws come from (frame, nuisance) alone, so runs repeat exactly.
"""
from __future__ import annotations

import argparse
import dataclasses
import zlib

import cv2
import numpy as np

from benchmarks.common import GREY, frames, geometric_mean, ratios_to_linear
from lipjax.data.augment import Augment, camera_noise, paint_texture, relight
from lipjax.data.synthetic import render_with_info
from lipjax.data.synthetic.renderer import Reflection
from lipjax.methods import get_completer
from research.common import pixel_classes

SCENES = (("rooms 200 points", "indoor", (480, 640), "uniform:200"),
          ("streets HDL-64", "outdoor", (352, 1216), "lidar:hdl64"))
WOBBLE_GRID = (12, 16)  # cells of the smooth relative depth error, rows x columns


def shifted(frame, px: int):
    """The image moved px pixels right and down against the depth (edge pixels repeated)."""
    rgb = np.pad(frame.rgb, ((px, 0), (px, 0), (0, 0)), mode="edge")[:frame.rgb.shape[0], :frame.rgb.shape[1]]
    return with_rgb(frame, rgb)


def depth_times(frame, factor: np.ndarray):
    """Depth times a per-pixel factor on the valid pixels (the samples are drawn from this depth afterwards)."""
    depth = np.where(frame.valid, frame.depth * factor, frame.depth).astype(np.float32)
    return dataclasses.replace(frame, depth=depth)


def noisy(frame, rel: float, rng: np.random.Generator):
    """Depth times 1 + rel n, n ~ N(0, 1) independently per pixel."""
    return depth_times(frame, 1.0 + rel * rng.standard_normal(frame.depth.shape))


def wobbled(frame, rel: float, rng: np.random.Generator):
    """Depth times 1 + rel f, f a standard normal field on WOBBLE_GRID cells, bicubically enlarged."""
    grid = rng.standard_normal(WOBBLE_GRID).astype(np.float32)
    field = cv2.resize(grid, frame.depth.shape[::-1], interpolation=cv2.INTER_CUBIC)
    return depth_times(frame, 1.0 + rel * field)


def with_rgb(frame, rgb: np.ndarray):
    """The frame with another image."""
    return dataclasses.replace(frame, rgb=np.ascontiguousarray(rgb))


def edges_lost(frame):
    """No valid depth at failure_look's depth-edge pixels, so no sample and no score there."""
    edge = pixel_classes(frame.rgb, frame.depth, frame.valid) == 0
    return dataclasses.replace(frame, valid=frame.valid & ~edge)


def textured(frame, patches: int, rng: np.random.Generator):
    """`paint_texture` at strength 0.7 on `patches` rectangles of the image."""
    rgb = frame.rgb
    for _ in range(patches):
        rgb = paint_texture(np.ascontiguousarray(rgb), 0.7, rng)
    return with_rgb(frame, rgb)


def reflected(frame, rng: np.random.Generator):
    """The test render `frame` drawn again with a reflecting floor (its depth, scene and noise unchanged)."""
    _, kind, split, index = frame.id.split("/")
    reflection = Reflection(float(rng.uniform(0.05, 0.3)), float(rng.uniform(0.5, 2.0)))
    again, _ = render_with_info(kind, split, int(index), *frame.depth.shape, reflection=reflection)
    return with_rgb(frame, again.rgb)


NUISANCES = {  # name -> (frame, rng) -> frame
    "none": lambda s, rng: s,
    "RGB shifted by 2 px": lambda s, rng: shifted(s, 2),
    "RGB shifted by 4 px": lambda s, rng: shifted(s, 4),
    "depth noise 1 %": lambda s, rng: noisy(s, 0.01, rng),
    "depth noise 3 %": lambda s, rng: noisy(s, 0.03, rng),
    "depth wobble 2 %": lambda s, rng: wobbled(s, 0.02, rng),
    "relit": lambda s, rng: with_rgb(s, relight(s.rgb, 0.7, rng)),
    "camera noise": lambda s, rng: with_rgb(s, camera_noise(s.rgb, Augment(sensor_noise=0.02, jpeg_prob=1.0), rng)),
    "texture, 3 patches": lambda s, rng: textured(s, 3, rng),
    "floor reflections": reflected,
    "no depth at edges": lambda s, rng: edges_lost(s),
}


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--model", default=None, help="a model name or path (default: the default path's choice)")
    ap.add_argument("--frames", type=int, default=8, help="test frames per scene")
    ap.add_argument("--only", default=None, help="comma-separated nuisances to run (default: all; 'none' is the "
                                                 "clean frame)")
    args = ap.parse_args(argv)
    names = list(NUISANCES) if args.only is None else [n.strip() for n in args.only.split(",")]
    unknown = sorted(set(names) - set(NUISANCES))
    if unknown:
        ap.error(f"unknown nuisance(s) {unknown}; choose from {list(NUISANCES)}")
    linear = get_completer("linear")
    print("| scene | nuisance | ratio to linear, image | grey image | image's worth (grey / image) | wins |")
    print("|---|---|---:|---:|---:|---:|")
    for scene, kind, size, spec in SCENES:
        clean = frames(kind, size, None, args.frames)
        for name in names:
            nuisance = NUISANCES[name]
            seeds = [zlib.crc32(f"{s.id}/{name}".encode()) for s in clean]
            spoilt = [nuisance(s, np.random.default_rng(seed)) for s, seed in zip(clean, seeds)]
            image, grey = zip(*(ratios_to_linear(args.model, linear, s, spec, (s.rgb, np.full_like(s.rgb, GREY)),
                                                 cross_check=False) for s in spoilt))
            g_image, g_grey = geometric_mean(image), geometric_mean(grey)
            print(f"| {scene} | {name} | {g_image:.3f} | {g_grey:.3f} | {g_grey / g_image:.3f} | "
                  f"{sum(r < 1 for r in image)}/{len(image)} |", flush=True)


if __name__ == "__main__":
    main()
