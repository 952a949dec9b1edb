"""NYU Depth v2 loaders: the h5 files of Ma & Karaman / FastDepth, and a prepared TFDS `nyu_depth_v2`.

Loaders yield the raw 480x640 frames; apply protocols.NYU_PAPER (or NYU_MA) for the benchmark crop.
"""
from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from lipjax.data.errors import dataset_error
from lipjax.data.folder import natural_key
from lipjax.data.frame import Frame, Intrinsics

# NYU Depth v2 RGB camera (the registered depth shares it), at 480x640, in pixels.
NYU_INTRINSICS = Intrinsics(fx=518.8579, fy=519.46961, cx=325.58245, cy=253.73617)

NYU_H5_LAYOUT = """\
<root>/nyudepthv2/{train,val}/<scene>/<n>.h5    (or <root> = the nyudepthv2 directory itself)
each .h5: 'rgb' uint8 (3, 480, 640), 'depth' float32 (480, 640) in metres"""
NYU_H5_SOURCE = (
    "Ma & Karaman, sparse-to-dense (https://github.com/fangchangma/sparse-to-dense): "
    "http://datasets.lids.mit.edu/sparse-to-dense/data/nyudepthv2.tar.gz (also used by FastDepth, CSPN, NLSPN)"
)


class NyuH5Dataset:
    """NYU Depth v2 in the h5 layout of Ma et al. / FastDepth (see NYU_H5_LAYOUT), as raw 480x640 Frames.

    Frames are sorted by scene, then by the numeric file stem. Frame.id = "nyu/<split>/<scene>/<stem>".

    Args:
      root: the nyudepthv2 directory, or its parent.
      split: "train" or "val".
      intrinsics: the camera of every frame (NYU_INTRINSICS; the h5 files carry none).
    """

    def __init__(self, root: str | os.PathLike, split: str = "val", intrinsics: Intrinsics = NYU_INTRINSICS):
        root = Path(root)
        if (root / "nyudepthv2").is_dir():
            root = root / "nyudepthv2"
        split_dir = root / split
        if split not in ("train", "val"):
            raise ValueError(f"NYU split must be 'train' or 'val', got {split!r}")
        if not split_dir.is_dir():
            raise dataset_error(f"NYU Depth v2 {split!r} split not found", split_dir, NYU_H5_LAYOUT, NYU_H5_SOURCE)
        self.files = sorted(split_dir.glob("*/*.h5"), key=lambda p: (natural_key(p.parent.name), natural_key(p.stem)))
        if not self.files:
            raise dataset_error("No .h5 frames found under", split_dir, NYU_H5_LAYOUT, NYU_H5_SOURCE)
        self.split = split
        self.intrinsics = intrinsics

    def __len__(self) -> int:
        return len(self.files)

    def __getitem__(self, index: int) -> Frame:
        path = self.files[index]
        rgb, depth = read_nyu_h5(path)
        return Frame.from_depth(rgb, depth, self.intrinsics, f"nyu/{self.split}/{path.parent.name}/{path.stem}")


def read_nyu_h5(path: str | os.PathLike) -> tuple[np.ndarray, np.ndarray]:
    """Reads one Ma et al. h5 frame -> (rgb (H, W, 3) uint8, depth (H, W) float32 metres)."""
    import h5py  # a core dependency; imported here so the module imports fast

    try:
        with h5py.File(path, "r") as f:
            rgb = np.asarray(f["rgb"])
            depth = np.asarray(f["depth"], dtype=np.float32)
    except (OSError, KeyError) as exc:
        raise dataset_error(f"Corrupt or unexpected NYU h5 file ({type(exc).__name__}: {exc})", path,
                            NYU_H5_LAYOUT, NYU_H5_SOURCE) from exc
    if rgb.ndim == 3 and rgb.shape[0] == 3:
        rgb = np.transpose(rgb, (1, 2, 0))  # stored channels-first (Matlab export)
    if rgb.dtype != np.uint8 or rgb.ndim != 3 or rgb.shape[2] != 3 or depth.shape != rgb.shape[:2]:
        raise dataset_error(f"Unexpected NYU h5 content: rgb {rgb.dtype} {rgb.shape}, depth {depth.shape}", path,
                            NYU_H5_LAYOUT, NYU_H5_SOURCE)
    if np.any(np.isnan(depth)) or np.any(depth < 0):
        raise dataset_error("NYU h5 depth has NaN or negative values", path, NYU_H5_LAYOUT, NYU_H5_SOURCE)
    return rgb, depth


TFDS_INSTALL_HINT = "pip install lipjax[tfds]  (installs tensorflow-datasets; TensorFlow itself is not needed)"
TFDS_SPLITS = {"train": "train", "val": "validation", "validation": "validation"}


class NyuTfdsDataset:
    """A prepared TFDS `nyu_depth_v2` read by random access without TensorFlow (tfds data sources).

    The data set must already be prepared in ArrayRecord format under data_dir (e.g. `tfds build nyu_depth_v2
    --file_format=array_record`). Features: 'image' uint8 (480, 640, 3), 'depth' float (480, 640) metres.
    Frame.id = "nyu/tfds/<split>/<index:05d>" (split "train" or "validation").

    Args:
      split: "train", "val" or "validation".
      data_dir: the TFDS data directory (None: TFDS's default, ~/tensorflow_datasets).
    """

    def __init__(self, split: str = "val", data_dir: str | os.PathLike | None = None,
                 intrinsics: Intrinsics = NYU_INTRINSICS):
        if split not in TFDS_SPLITS:
            raise ValueError(f"NYU TFDS split must be one of {sorted(TFDS_SPLITS)}, got {split!r}")
        try:
            import tensorflow_datasets as tfds  # optional extra, imported only when used
        except ImportError as exc:
            raise dataset_error(f"tensorflow_datasets is not installed; {TFDS_INSTALL_HINT}", None) from exc
        self.split = TFDS_SPLITS[split]
        self.intrinsics = intrinsics
        try:
            builder = tfds.builder("nyu_depth_v2", data_dir=None if data_dir is None else os.fspath(data_dir))
            self.source = builder.as_data_source(split=self.split)
        except Exception as exc:  # noqa: BLE001 - tfds raises many types for "not prepared"
            raise dataset_error(
                f"TFDS nyu_depth_v2 is not prepared as ArrayRecord ({type(exc).__name__}: {exc}) in data_dir",
                data_dir if data_dir is not None else "~/tensorflow_datasets",
                "<data_dir>/nyu_depth_v2/<version>/nyu_depth_v2-{train,validation}.array_record-*",
                "https://www.tensorflow.org/datasets/catalog/nyu_depth_v2 ; prepare with "
                "`tfds build nyu_depth_v2 --file_format=array_record`",
            ) from exc

    def __len__(self) -> int:
        return len(self.source)

    def __getitem__(self, index: int) -> Frame:
        if not 0 <= index < len(self):
            raise IndexError(index)
        example = self.source[index]
        depth = np.asarray(example["depth"], dtype=np.float32)
        if depth.ndim == 3:
            depth = depth[..., 0]
        return Frame.from_depth(np.asarray(example["image"], np.uint8), depth, self.intrinsics,
                                f"nyu/tfds/{self.split}/{index:05d}")
