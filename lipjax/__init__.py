"""lipjax: depth completion from RGB and sparse LiDAR as a linear inverse problem, solved by unrolled ADMM with
a learned, RGB-guided proximal network (JAX / Flax).

Depth is in metres everywhere; 0 means "no measurement".

    import lipjax
    dense = lipjax.complete(rgb_uint8_hw3, sparse_depth_m_hw)          # shipped default model
    model = lipjax.load_model("lip-cnn-outdoor"); dense = model(rgb, sparse)
"""
from lipjax.admm import Trajectory, unrolled_admm
from lipjax.inference import Completer, InputError, load_model
from lipjax.interfaces import parameter_count
from lipjax.methods import complete
from lipjax.model import LIPConfig, presets
from lipjax.shipped import available as available_models
from lipjax.operators import dual_update, x_update
from lipjax.priors.network import NetworkPrior, network_preset
from lipjax.utils import enable_compilation_cache

__all__ = [
    "Completer",
    "InputError",
    "LIPConfig",
    "NetworkPrior",
    "Trajectory",
    "available_models",
    "complete",
    "dual_update",
    "enable_compilation_cache",
    "load_model",
    "network_preset",
    "parameter_count",
    "presets",
    "unrolled_admm",
    "x_update",
]
__version__ = "0.1.0"
