"""The one exception data loaders raise, with messages that say how to fix the problem.

A missing or corrupt file in a data set is almost always a setup problem (wrong root, partial download,
wrong unzip level), so every message names the offending path, the layout the loader expected and where
the data set comes from, instead of a bare FileNotFoundError deep inside h5py or cv2.
"""
from __future__ import annotations

import os


class DatasetError(ValueError):
    """A data set path is missing, malformed or holds a corrupt / unexpected file.

    Subclasses ValueError so callers that validate inputs generically still catch it.
    """


def dataset_error(problem: str, path: str | os.PathLike | None, layout: str = "", source: str = "") -> DatasetError:
    """Builds a DatasetError whose message is: problem + path, expected layout, where the data comes from.

    Args:
      problem: what is wrong, e.g. "NYU root not found".
      path: the offending file or directory (None when not about one path).
      layout: the expected directory layout (multi-line text), shown indented.
      source: where to get the data set (URL / how it is prepared).
    """
    lines = [f"{problem}: {os.fspath(path)}" if path is not None else problem]
    if layout:
        lines.append("Expected layout:")
        lines.extend("    " + line for line in layout.strip("\n").splitlines())
    if source:
        lines.append(f"Data set source: {source}")
    return DatasetError("\n".join(lines))
