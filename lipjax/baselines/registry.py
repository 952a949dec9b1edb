"""Classical completers by name, for configs and command lines: `make_completer("ip_basic", extrapolate=True)`."""
from __future__ import annotations

from collections.abc import Callable
from typing import Any

from lipjax.baselines.classical import (
    ColorizationFill,
    IPBasicAdaptiveFill,
    IPBasicFill,
    IPBasicMultiscaleFill,
    LinearFill,
    NearestFill,
)
from lipjax.baselines.completer import DepthCompleter

COMPLETERS: dict[str, Callable[..., DepthCompleter]] = {
    "nearest": NearestFill,
    "linear": LinearFill,
    "ip_basic": IPBasicFill,
    "ip_basic_multiscale": IPBasicMultiscaleFill,
    "ip_basic_adaptive": IPBasicAdaptiveFill,
    "colorization": ColorizationFill,
}


def make_completer(name: str, **kwargs: Any) -> DepthCompleter:
    """Builds the completer registered as `name`, with dataclass fields overridden by kwargs."""
    if name not in COMPLETERS:
        raise ValueError(f"unknown completer {name!r}; known: {sorted(COMPLETERS)}")
    return COMPLETERS[name](**kwargs)
