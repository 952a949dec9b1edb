"""A depth sensor beside the camera: what its parallax (returns seen through edges, shadowed surfaces) costs a model.

The model's own estimate is scored (`cross_check=False`): the default path's check against the linear fill
(lipjax.crosscheck) would mix that fill into what is measured here.

    python -m research.sensor_offset [--model PATH] [--frames 8]

Frames of the synthetic test split (never trained on), through the default path at full size
(`lipjax.inference.complete_frame`), each once with the samples drawn at the camera (as every other benchmark) and
once measured from a sensor beside it (`lipjax.data.sampling.Parallax.at`, lipjax.data.parallax):

    streets 352x1216   HDL-64 scan from KITTI's rig, the LiDAR at (0.06, -0.08, -0.27) m from the colour camera
                       (right, up, behind; its beams start there, so the sampler's own mount offsets are zeroed)
    rooms 480x640      1,000 points from an RGB-D camera's depth sensor 5 cm to the right of its colour sensor
    rooms 480x640      dense depth with holes (`holes:0.3`) from that depth sensor

Per setting: the geometric-mean RMSE ratio to the Delaunay linear fill of the same samples (unsampled valid pixels;
seed 0) and the wins, at the camera and from the sensor beside it.
"""
from __future__ import annotations

import argparse

import numpy as np

from benchmarks.common import ratio_to_linear
from lipjax.data.sampling import LidarSampler, Parallax, sampler_from_spec
from lipjax.data.synthetic import SyntheticDataset
from lipjax.methods import get_completer

KITTI_LIDAR_M = (0.06, -0.08, -0.27)  # Velodyne from KITTI's left colour camera (x right, y down, z forward)
RGBD_DEPTH_SENSOR_M = (0.05, 0.0, 0.0)
ROOM, STREET = (480, 640), (352, 1216)
SETTINGS = (  # (name, scene kind, size, sampler at the camera, the same sensor beside it)
    ("streets HDL-64, KITTI rig", "outdoor", STREET, LidarSampler.hdl64(),
     Parallax.at(LidarSampler.hdl64(mount_height_m=0.0, mount_forward_m=0.0), KITTI_LIDAR_M)),
    ("rooms 1000 points, RGB-D", "indoor", ROOM, sampler_from_spec("uniform:1000"),
     Parallax.at(sampler_from_spec("uniform:1000"), RGBD_DEPTH_SENSOR_M)),
    ("rooms holes:0.3, RGB-D", "indoor", ROOM, sampler_from_spec("holes:0.3"),
     Parallax.at(sampler_from_spec("holes:0.3"), RGBD_DEPTH_SENSOR_M)),
)


def geometric(r) -> str:
    r = np.asarray(r)
    return f"{np.exp(np.log(r).mean()):.3f} ({int((r < 1).sum())}/{len(r)})"


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--model", default=None, help="a model name or path (default: the default path's choice)")
    ap.add_argument("--frames", type=int, default=8, help="test frames per setting")
    args = ap.parse_args(argv)
    linear = get_completer("linear")
    print(f"{'setting':28s} {'at the camera':>16s} {'sensor beside it':>18s}   geometric mean (wins) of RMSE / linear")
    for name, kind, size, at_camera, beside in SETTINGS:
        frames = SyntheticDataset(kind, "test", size=args.frames, height=size[0], width=size[1])
        plain = [ratio_to_linear(args.model, linear, s, at_camera, cross_check=False) for s in frames]
        offset = [ratio_to_linear(args.model, linear, s, beside, cross_check=False) for s in frames]
        print(f"{name:28s} {geometric(plain):>16s} {geometric(offset):>18s}", flush=True)


if __name__ == "__main__":
    main()
