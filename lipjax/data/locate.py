"""Where the paper's data sets are looked for when no folder is given: an environment variable, then the usual places.

    root = find_data_root("nyu")        # a Path, or None when the data set is not on this machine

The experiments that reproduce the paper's tables (`python -m experiments.nyu_200pts`, `experiments.kitti_dc`) run
on the real data set when it is on disk and on the embedded synthetic data otherwise, saying which. A usual place
counts only when it holds the layout its loader reads (`LAYOUT_MARKERS`), so an empty or unrelated folder of the same
name never turns the synthetic run into an error. A folder the user named (`--data-dir`, or the environment variable)
is always used, and its loader says what is missing.
"""
from __future__ import annotations

import os
from pathlib import Path

# The environment variable that names each data set's folder, looked at first.
ROOT_ENV = {"nyu": "LIPJAX_NYU_DIR", "kitti": "LIPJAX_KITTI_DIR"}
# Then these folders (relative ones from the working directory), in order.
USUAL_PLACES = {
    "nyu": ("data/nyudepthv2", "~/data/nyudepthv2", "/data/nyudepthv2"),
    "kitti": ("data/kitti_depth", "~/data/kitti_depth", "/data/kitti_depth"),
}
# What a folder must hold, as glob patterns under it (any one matching is enough; the loaders accept the same).
LAYOUT_MARKERS = {
    "nyu": ("val/*/*.h5", "nyudepthv2/val/*/*.h5"),  # NyuH5Dataset: the nyudepthv2 folder or its parent
    "kitti": ("depth_selection/val_selection_cropped/image/*.png", "val_selection_cropped/image/*.png",
              "image/*.png"),  # KittiSelection: the root, depth_selection/ or val_selection_cropped/ itself
}


def holds(root: str | os.PathLike, data_set: str) -> bool:
    """Whether folder `root` holds `data_set`'s layout (LAYOUT_MARKERS)."""
    root = Path(root).expanduser()
    return root.is_dir() and any(next(root.glob(marker), None) is not None for marker in LAYOUT_MARKERS[data_set])


def find_data_root(data_set: str) -> Path | None:
    """The folder named by $ROOT_ENV[data_set] if set (as it is: the loader checks it), else the first of
    USUAL_PLACES[data_set] that holds the data set's layout, else None."""
    if data_set not in ROOT_ENV:
        raise ValueError(f"unknown data set {data_set!r}; known: {', '.join(sorted(ROOT_ENV))}")
    if os.environ.get(ROOT_ENV[data_set]):
        return Path(os.environ[ROOT_ENV[data_set]]).expanduser()
    return next((Path(p).expanduser() for p in USUAL_PLACES[data_set] if holds(p, data_set)), None)


def not_found_note(data_set: str) -> str:
    """Where `find_data_root` looked, for the line that says the synthetic data is used instead."""
    return f"--data-dir, ${ROOT_ENV[data_set]}, {', '.join(USUAL_PLACES[data_set])}"
