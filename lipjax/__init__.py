"""lipjax: depth completion from RGB and sparse LiDAR as a linear inverse problem, solved by unrolled ADMM with
a learned, RGB-guided proximal network (JAX / Flax).

Depth is in metres everywhere; 0 means "no measurement".

    import lipjax
    dense = lipjax.complete(rgb_uint8_hw3, sparse_depth_m_hw)          # shipped default model
    model = lipjax.load_model("lip-cnn-outdoor"); dense = model(rgb, sparse)

The names below are imported on first use (PEP 562): `import lipjax` alone loads no JAX, so that `lipjax --help`
answers at once.
"""
from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:  # what the lazy names are, for readers and type checkers
    from lipjax.admm import Trajectory, unrolled_admm
    from lipjax.inference import Completer, InputError, load_model
    from lipjax.interfaces import parameter_count
    from lipjax.methods import complete
    from lipjax.model import LIPConfig, presets
    from lipjax.operators import dual_update, x_update
    from lipjax.priors.network import NetworkPrior, network_preset
    from lipjax.shipped import available as available_models
    from lipjax.utils import enable_compilation_cache

# name -> (module, attribute): the public names, each imported from its module when first asked for
_LAZY = {
    "Completer": ("lipjax.inference", "Completer"),
    "InputError": ("lipjax.inference", "InputError"),
    "LIPConfig": ("lipjax.model", "LIPConfig"),
    "NetworkPrior": ("lipjax.priors.network", "NetworkPrior"),
    "Trajectory": ("lipjax.admm", "Trajectory"),
    "available_models": ("lipjax.shipped", "available"),
    "complete": ("lipjax.methods", "complete"),
    "dual_update": ("lipjax.operators", "dual_update"),
    "enable_compilation_cache": ("lipjax.utils", "enable_compilation_cache"),
    "load_model": ("lipjax.inference", "load_model"),
    "network_preset": ("lipjax.priors.network", "network_preset"),
    "parameter_count": ("lipjax.interfaces", "parameter_count"),
    "presets": ("lipjax.model", "presets"),
    "unrolled_admm": ("lipjax.admm", "unrolled_admm"),
    "x_update": ("lipjax.operators", "x_update"),
}
__all__ = sorted(_LAZY)
__version__ = "0.1.0"


def __getattr__(name: str) -> Any:
    """A public name of `_LAZY`, or a submodule not imported yet (`lipjax.uncertainty` after `import lipjax`)."""
    if name in _LAZY:
        module, attribute = _LAZY[name]
        value = getattr(importlib.import_module(module), attribute)
        globals()[name] = value  # asked once
        return value
    try:
        return importlib.import_module(f"{__name__}.{name}")
    except ModuleNotFoundError as exc:
        if exc.name != f"{__name__}.{name}":  # the submodule exists and lacks something itself
            raise
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_LAZY))
