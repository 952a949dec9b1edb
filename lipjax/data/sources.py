"""One factory for every data set training and evaluation read: `open_source(data_config, split)`.

    source          root                                   default protocol   split
    synthetic       (none: rendered on the fly)            none               the set's own train / val
    rendered        a folder of `lipjax data render`,      none               train: the folder(s); val: synthetic
                    or several "A,B" of one frame size                        val of the (first) render's kind
    nyu_h5          nyudepthv2/ (Ma et al. h5 layout)      nyu_paper          train / val folders
    nyu_tfds        TFDS data_dir (prepared ArrayRecord)   nyu_paper          train / validation
    kitti_dc        depth_root (raw_root: KITTI raw)       kitti_paper        train / val folders
    kitti_selection holds depth_selection/                 kitti_selection    val only: val_selection_cropped
    kitti_odometry  holds sequences/                       kitti_paper        last 5 % of each sequence is val
    tartanair       holds the environment folders          tartanair          90 / 5 / 5 by trajectory
    folder          rgb/ depth/ [sparse/], or train/ val/  none               train/ val/ if present, else the
                                                                              last 5 % of the frames is val

Sparse input: a sampler spec of lipjax.data.sampling ("uniform:200", "lidar:hdl64", mixtures "a|b"), or
"input" / "input:N" for the data set's own sparse input: KITTI's real `velodyne_raw` scan, or a folder's
sparse/<stem> maps (same format and depth scale as depth/); ":N" keeps exactly N of its points. "hide" / "hide:F"
(a folder only, self-supervised: lipjax.data.hidden): the folder's sparse/ maps are its ground truth (no depth/
needed), each frame's input is its sparse map less a share F of it, the hidden samples its ground truth.

Depth in metres throughout; `DataConfig` (lipjax.train.config) names the source, its root and the rest.
"""
from __future__ import annotations

import dataclasses
import functools
import os
from pathlib import Path
from typing import Any

import numpy as np

from lipjax.data.errors import dataset_error
from lipjax.data.frame import Frame
from lipjax.data.hidden import AtWorkingSize, HiddenInput, hide_share
from lipjax.data.protocols import EvalProtocol, ProtocolView, get_protocol
from lipjax.data.sampling import SparseSampler, draws_scan_lines, example_rng, sampler_from_spec, subsample_exact
from lipjax.interfaces import MIXED_SCENES

SOURCES = ("synthetic", "rendered", "nyu_h5", "nyu_tfds", "kitti_dc", "kitti_selection", "kitti_odometry", "tartanair",
           "folder")
DEFAULT_PROTOCOLS = {"nyu_h5": "nyu_paper", "nyu_tfds": "nyu_paper", "kitti_dc": "kitti_paper",
                     "kitti_selection": "kitti_selection", "kitti_odometry": "kitti_paper", "tartanair": "tartanair"}
VAL_TAIL_FRACTION = 0.05  # sources without a val split hold out the last 5 % of each sequence / folder
OWN_INPUT = "input"
NO_PROTOCOL = "none"  # data.protocol="none": frames as they are, even where the source has a default


@dataclasses.dataclass(frozen=True)
class Source:
    """A data set of (protocol-applied) Frames and the sampler that draws its sparse input."""

    dataset: Any
    sampler: SparseSampler


class Subset:
    """dataset[indices[i]] as an indexable data set (picklable when `dataset` is)."""

    def __init__(self, dataset: Any, indices):
        self.dataset, self.indices = dataset, np.asarray(indices, np.int64)

    def __len__(self) -> int:
        return len(self.indices)

    def __getitem__(self, index: int) -> Frame:
        return self.dataset[int(self.indices[index])]


def tail_split(groups: list[str], split: str, fraction: float = VAL_TAIL_FRACTION) -> np.ndarray:
    """Indices of `split` when each group (sequence) keeps its last `fraction` of frames (>= 1) for val.

    groups: the group name of every frame, frames of a group in time order."""
    names = np.asarray(groups)
    val = np.zeros(len(names), bool)
    for name in dict.fromkeys(groups):
        where = np.flatnonzero(names == name)
        val[where[len(where) - max(1, round(fraction * len(where))):]] = True
    return np.flatnonzero(val if split == "val" else ~val)


@dataclasses.dataclass(frozen=True)
class FolderInput:
    """Sampler: the folder's own sparse map <root>/sparse/<stem>.png|.npy (PNG: metres = value / depth_scale),
    optionally sub-sampled to exactly num_points (keyed by the frame id). No protocol: folders train as is."""

    directory: str
    depth_scale: float | None
    id_prefix: str
    num_points: int | None = None

    def __call__(self, frame: Frame, seed: int = 0) -> np.ndarray:
        sparse = self.read(frame.id)
        if sparse.shape != frame.shape:
            raise dataset_error(f"Sparse input {sparse.shape} and depth {frame.shape} sizes differ",
                                self._path(frame.id[len(self.id_prefix) + 1:]))
        if self.num_points is not None:
            sparse = subsample_exact(sparse, self.num_points, example_rng(seed, frame.id))
        return sparse

    def read(self, frame_id: str) -> np.ndarray:
        """The whole sparse map (H, W) float32 metres of the frame whose Frame.id is `frame_id`, unchecked against
        any size (lipjax.data.hidden.HiddenInput reads it at full size for a Frame at its working size)."""
        from lipjax.data.folder import read_depth

        path = self._path(frame_id[len(self.id_prefix) + 1:])
        return read_depth(path, self.depth_scale if path.suffix.lower() == ".png" else None)

    def _path(self, key: str) -> Path:
        """sparse/<key>.png|.npy; for frames paired by number (key "00050": rgb_00050.jpg with
        sync_depth_00050.png), the sparse map whose stem ends in that number."""
        directory = Path(self.directory)
        for suffix in (".png", ".npy"):
            if (directory / f"{key}{suffix}").is_file():
                return directory / f"{key}{suffix}"
        if key in self._by_number:
            return self._by_number[key]
        raise dataset_error(f"No sparse input for frame {key!r} (sampler 'input' needs sparse/<stem>, named as in "
                            "rgb/ or depth/)", directory / f"{key}.png")

    @functools.cached_property
    def _by_number(self) -> dict[str, Path]:
        from lipjax.data.folder import files_by_number

        return files_by_number(Path(self.directory)) if Path(self.directory).is_dir() else {}


def own_points(spec: str) -> int | None:
    _, _, n = spec.partition(":")
    try:
        return int(n) if n else None
    except ValueError:
        raise ValueError(f"sampler spec {spec!r}: expected 'input' or 'input:N' with an integer N") from None


def uses_intrinsics(spec: str) -> bool:
    """Whether the sparse input of `spec` (a lipjax.data.sampling spec, "input[:N]" or "hide[:F]") reads the camera
    intrinsics: only the LiDAR simulation does."""
    return spec.split(":")[0].strip() != OWN_INPUT and hide_share(spec) is None and draws_scan_lines(spec)


def folder_split_root(root: Path, split: str) -> tuple[Path, bool]:
    """(folder holding rgb/ and depth/ for this split, whether the split is a folder of its own)."""
    if (root / "train").is_dir() and (root / "val").is_dir():
        return root / split, True
    return root, False


def _raw_dataset(data: Any, split: str, render_frames: bool = False) -> tuple[Any, Any]:
    """(data set of raw Frames of `split`, the object the source's own input comes from or None)."""
    source, root = data.source, data.root
    if source == "synthetic":
        from lipjax.data.synthetic.dataset import EXTRAS, MixedSyntheticDataset, SyntheticDataset

        size = data.val_images if split == "val" else None
        focal = (1.0, 1.0) if split == "val" else data.focal_range  # validation: the reference camera
        clutter = 0.0 if split == "val" else data.clutter_prob  # validation: the rooms as built
        foliage = 0.0 if split == "val" else data.foliage_prob  # validation: solid trees
        if data.kind == MIXED_SCENES:
            far_view = 0.0 if split == "val" else data.far_view_prob  # validation: closed rooms
            return MixedSyntheticDataset(split, size, data.height, data.width, focal, far_view, clutter,
                                         foliage), None
        if data.far_view_prob:
            raise ValueError(f"data.far_view_prob needs rooms and streets (data.kind='{MIXED_SCENES}'), got "
                             f"data.kind={data.kind!r}; add --set data.kind={MIXED_SCENES} or data.far_view_prob=0")
        for name, (wanted, scenes) in EXTRAS.items():
            if getattr(data, name) and data.kind != wanted:
                raise ValueError(f"data.{name} needs {scenes} (data.kind='{wanted}' or '{MIXED_SCENES}'), got "
                                 f"data.kind={data.kind!r}; leave data.{name} at 0")
        return SyntheticDataset(data.kind, split, size, data.height, data.width, focal, clutter, foliage), None
    if root is None:
        raise ValueError(f"data.source={source!r} needs data.root; add --set data.root=DIR")
    if source == "rendered":
        from lipjax.data.rendered import open_rendered
        from lipjax.data.synthetic import SyntheticDataset

        dataset = open_rendered(root)  # reads index.json only: the kind check holds for both splits
        first = dataset.kinds[0]
        if first != data.kind:  # several folders: the first names the val split and the depth range
            raise ValueError(f"{root} holds {first} renders{' first' if len(dataset.kinds) > 1 else ''} but "
                             f"data.kind={data.kind!r}; add --set data.kind={first}")
        if split == "val" and not render_frames:  # the fixed on-the-fly val set of the kind: comparable across runs
            return SyntheticDataset(data.kind, "val", size=data.val_images, height=data.height, width=data.width), None
        return dataset, None
    if source == "nyu_h5":
        from lipjax.data.nyu import NyuH5Dataset

        return NyuH5Dataset(root, split), None
    if source == "nyu_tfds":
        from lipjax.data.nyu import NyuTfdsDataset

        return NyuTfdsDataset(split, data_dir=root), None
    if source == "kitti_dc":
        from lipjax.data.kitti import KittiDepthCompletion

        dataset = KittiDepthCompletion(root, data.raw_root or root, split)
        return dataset, dataset
    if source == "kitti_selection":
        from lipjax.data.kitti import KittiSelection

        if split != "val":
            raise ValueError("data.source='kitti_selection' (depth_selection/val_selection_cropped) is a val split "
                             "only; train on data.source=kitti_dc")
        dataset = KittiSelection(root)
        return dataset, dataset
    if source == "kitti_odometry":
        from lipjax.data.kitti_odometry import KittiOdometry

        dataset = KittiOdometry(root)
        return Subset(dataset, tail_split([seq for seq, _, _ in dataset.frames], split)), None
    if source == "tartanair":
        from lipjax.data.tartanair import TartanAirDataset

        return TartanAirDataset(root, split), None
    if source == "folder":
        from lipjax.data.folder import SPARSE_DIR, FolderDataset

        folder, own_split = folder_split_root(Path(root), split)
        spec = data.train_sampler if split == "train" else data.val_sampler
        hide = hide_share(spec) is not None  # rgb/ and sparse/ alone, at the working size (lipjax.data.hidden)
        dataset = FolderDataset(folder, depth_scale=data.depth_scale, id_prefix=f"folder/{split}",
                                intrinsics_needed=uses_intrinsics(spec), depth_dir=SPARSE_DIR if hide else "depth")
        own = FolderInput(os.fspath(folder / SPARSE_DIR), data.depth_scale, dataset.id_prefix)
        dataset = ProtocolView(dataset, AtWorkingSize()) if hide else dataset
        if own_split:
            return dataset, own
        return Subset(dataset, tail_split(["all"] * len(dataset), split)), own
    raise ValueError(f"unknown data.source {source!r}; choose one of {SOURCES}")


def applied_protocol(data: Any) -> EvalProtocol | None:
    """The protocol open_source applies to a DataConfig's frames: data.protocol, else the source's default; None
    for data.protocol="none" or a source without one."""
    name = data.protocol or DEFAULT_PROTOCOLS.get(data.source)
    return get_protocol(name) if name not in (None, NO_PROTOCOL) else None


def range_protocol(data: Any) -> EvalProtocol | None:
    """The protocol whose depth range evaluation on a DataConfig's frames uses: the applied one, else (frames as
    they are, data.protocol="none") the source's default, synthetic_<data.kind> for the synthetic scenes; None for
    a folder."""
    if data.source in ("synthetic", "rendered"):
        default = "synthetic_outdoor" if data.kind == MIXED_SCENES else f"synthetic_{data.kind}"  # 0-80 m holds both
    else:
        default = DEFAULT_PROTOCOLS.get(data.source)
    return applied_protocol(data) or (get_protocol(default) if default else None)


def open_source(data: Any, split: str, *, render_frames: bool = False) -> Source:
    """The Source of a DataConfig's `split` ("train" or "val"): protocol applied, val cut to val_images frames.

    The train split uses data.train_sampler, val data.val_sampler (see the module docstring for "input").
    source="rendered": data.kind must be the render's (index.json), for either split; the val split is the
    synthetic val split of that kind, as training validates, unless render_frames=True (evaluating the render:
    the folder's frames for either split).
    """
    if split not in ("train", "val"):
        raise ValueError(f"split must be 'train' or 'val', got {split!r}")
    dataset, own = _raw_dataset(data, split, render_frames)
    protocol = applied_protocol(data)
    spec = data.train_sampler if split == "train" else data.val_sampler
    if hide_share(spec) is not None:
        if data.source != "folder":
            raise ValueError(f"sampler {spec!r} (self-supervised: samples hidden from a folder's own sparse/ maps) "
                             f"needs data.source='folder', got {data.source!r}")
        sampler = HiddenInput(own, hide_share(spec))
    elif spec.split(":")[0].strip() == OWN_INPUT:
        if own is None:
            raise ValueError(f"sampler {spec!r}: data.source={data.source!r} has no sparse input of its own; "
                             "use a spec such as uniform:200")
        if data.source in ("kitti_dc", "kitti_selection"):
            from lipjax.data.kitti import KittiLidarInput

            sampler = KittiLidarInput(own, protocol, own_points(spec))
        else:
            sampler = dataclasses.replace(own, num_points=own_points(spec))
    else:
        sampler = sampler_from_spec(spec)
    if protocol is not None:
        dataset = ProtocolView(dataset, protocol)
    if (split == "val" and data.source != "synthetic" and data.val_images is not None
            and len(dataset) > data.val_images):
        dataset = Subset(dataset, np.arange(data.val_images))
    if len(dataset) == 0:
        raise ValueError(f"data.source={data.source!r} at {data.root}: the {split} split is empty")
    return Source(dataset, sampler)
