"""Hand-crafted depth completers: no learned parameters, all `DepthCompleter`s (lipjax.interfaces); by
name through the one resolver, lipjax.methods.get_completer:

    completer(rgb (H, W, 3) uint8, sparse (H, W) float32 metres, 0 = no sample) -> (H, W) float32 metres

  NearestFill             nearest sample (Voronoi), exact at samples                ignores RGB   nearest.py
  LinearFill              Delaunay piecewise-linear, nearest outside the hull       ignores RGB   interpolate.py
  IPBasicFill             IP-Basic `fill_in_fast` (Ku et al. 2018); 0 where it      ignores RGB   ipbasic.py
                          leaves no depth
  IPBasicMultiscaleFill   IP-Basic `fill_in_multiscale`; 0 where it leaves no depth ignores RGB   ipbasic.py
  IPBasicAdaptiveFill     IP-Basic with density-adaptive kernels, fills every pixel ignores RGB   ipbasic.py
  ColorizationFill        Levin et al. 2004 colourisation (NYU toolbox), exact at   RGB-guided    colorization.py
                          samples
  LIPWavelet              the paper's LIP+Wavelet baseline: the ADMM solver with    ignores RGB   lip_wavelet.py
                          the wavelet soft-thresholding prox (lipjax.priors.wavelet)

`fill_holes` gives depth to the pixels a method leaves at 0 (the nearest pixel's with depth): what
`lipjax complete --fill-all` adds to the methods that leave some (ip_basic, ip_basic_multiscale).

Each checks its inputs with lipjax.inputs.check_frame: InputError (a ValueError) for an empty sparse map,
mismatched shapes, NaN / inf or negative depth.
"""
from __future__ import annotations

from lipjax.classical.colorization import ColorizationFill, colorization_fill
from lipjax.classical.interpolate import LinearFill, linear_fill
from lipjax.classical.ipbasic import (
    IPBasicAdaptiveFill,
    IPBasicFill,
    IPBasicMultiscaleFill,
    ip_basic,
    ip_basic_adaptive,
    ip_basic_multiscale,
)
from lipjax.classical.nearest import NearestFill, fill_holes, nearest_fill

__all__ = [
    "ColorizationFill",
    "IPBasicAdaptiveFill",
    "IPBasicFill",
    "IPBasicMultiscaleFill",
    "LinearFill",
    "NearestFill",
    "colorization_fill",
    "fill_holes",
    "ip_basic",
    "ip_basic_adaptive",
    "ip_basic_multiscale",
    "linear_fill",
    "nearest_fill",
]

