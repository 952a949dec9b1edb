"""Floor reflections (lipjax.data.synthetic.renderer.Reflection): the mirror image lands where the reflected ray's
geometry says, weighted by Schlick's Fresnel term; depth and labels are untouched; off, the frame is as before."""
from __future__ import annotations

import numpy as np
import pytest

from lipjax.data import synthetic as S
from lipjax.data.frame import Intrinsics
from lipjax.data.synthetic.constants import _ROAD, _WALL
from lipjax.data.synthetic.materials import _Mat
from lipjax.data.synthetic.primitives import _Box, _Ground
from lipjax.data.synthetic.renderer import Reflection, _lit, _reflect, render_scene
from lipjax.data.synthetic.scene import Scene, _camera_rotation

H, W = 96, 64
INTR = Intrinsics(fx=60.0, fy=60.0, cx=(W - 1) / 2, cy=(H - 1) / 2)
CAMERA_HEIGHT_M, WALL_DISTANCE_M, WALL_HEIGHT_M = 1.5, 10.0, 3.0


def _solid(colour):
    return lambda u, v, fp: np.broadcast_to(np.asarray(colour, np.float32)[:, None], (3, u.shape[0]))


def _wall_scene() -> Scene:
    """A black matte ground and a self-lit white wall WALL_DISTANCE_M ahead, nothing else, no light: the
    radiance is 1 on the wall and 0 everywhere else, so a floor pixel's radiance is its mirror image's."""
    ground = _Ground(_ROAD, _Mat(_solid((0.0, 0.0, 0.0))))
    wall = _Box((0.0, WALL_HEIGHT_M / 2, WALL_DISTANCE_M), (50.0, WALL_HEIGHT_M / 2, 0.1), _WALL,
                _Mat(_solid((1.0, 1.0, 1.0)), emit=1.0))
    return Scene([ground, wall], np.array([0.0, CAMERA_HEIGHT_M, 0.0]), _camera_rotation(0.0, 0.0, 0.0), [],
                 np.zeros((3, 1), np.float32), 0.0, 100.0)


def _radiance(scene: Scene, reflection: Reflection | None, intr: Intrinsics = INTR, size=(H, W)):
    """((3, h, w) linear radiance of `scene` with `reflection` blended in, (h, w) labels) at `size` (h, w)."""
    h, w = size
    _, s, lin = _lit(scene, scene.prims, h, w, intr)
    if reflection is not None:
        _reflect(scene, scene.prims, s, lin, reflection, intr, h, w)
    return lin.reshape(3, h, w), s.labels.reshape(h, w)


def test_the_mirror_image_lies_where_the_reflected_ray_meets_the_wall_weighted_by_fresnel():
    """The camera's ray through row v (yn = (v - cy) / fy below the horizon) meets the ground at z = h / yn and,
    reflected, rises with slope yn: it meets the wall (z = D, heights 0..H_w) iff h / D <= yn <= (h + H_w) / D.
    There a floor pixel shows the wall with weight F = s + (1 - s) (1 - cos theta)^5, cos theta = yn / |(xn, yn, 1)|;
    elsewhere the black ground. (Rows within 3 px of the band's ends are left out: the mirror image is rendered at
    half size and upsampled.)"""
    scene = _wall_scene()
    strength = 0.2
    lin = _radiance(scene, Reflection(strength, blur_px=0.0))[0]
    rows = np.arange(H)
    yn = (rows - INTR.cy) / INTR.fy
    lo, hi = CAMERA_HEIGHT_M / WALL_DISTANCE_M, (CAMERA_HEIGHT_M + WALL_HEIGHT_M) / WALL_DISTANCE_M
    ground = yn > lo  # the ground in front of the wall: the wall's own bottom edge is at yn = h / D
    inside = ground & (yn > lo + 3 / INTR.fy) & (yn < hi - 3 / INTR.fy)
    outside = ground & (yn > hi + 3 / INTR.fy)
    np.testing.assert_array_equal(_radiance(scene, None)[0][:, ground], 0.0)  # matte, the ground is black
    assert inside.sum() >= 10 and outside.sum() >= 10
    xn = (np.arange(W) - INTR.cx) / INTR.fx
    cos = yn[:, None] / np.sqrt(xn[None, :] ** 2 + yn[:, None] ** 2 + 1.0)
    fresnel = strength + (1.0 - strength) * (1.0 - cos) ** 5
    for c in range(3):
        np.testing.assert_allclose(lin[c][inside], fresnel[inside], rtol=1e-4)
        np.testing.assert_allclose(lin[c][outside], 0.0, atol=1e-6)


@pytest.mark.parametrize("kind", S.SYNTHETIC_KINDS)
def test_reflections_change_the_floor_only_never_the_depth(kind):
    frame, info = S.render_with_info(kind, "val", 4, 48, 64)
    shiny, shiny_info = S.render_with_info(kind, "val", 4, 48, 64, reflection=Reflection(0.3, 1.0))
    np.testing.assert_array_equal(shiny.depth, frame.depth)
    np.testing.assert_array_equal(shiny_info.labels, info.labels)
    scene_rng, noise_rng = S.frame_rngs(kind, "val", 4)
    matte = render_scene(S.build_scene(kind, scene_rng), 48, 64, S.intrinsics_for(kind, 48, 64), noise_rng)[0]
    np.testing.assert_array_equal(matte, frame.rgb)  # off: the frame as every data set renders it
    scene = S.build_scene(kind, S.frame_rngs(kind, "val", 4)[0])
    intr = S.intrinsics_for(kind, 48, 64)
    (matte_lin, labels), (shiny_lin, _) = (_radiance(scene, r, intr, (48, 64)) for r in (None, Reflection(0.3, 1.0)))
    floor = np.isin(labels, (S.LABELS.index("floor"), S.LABELS.index("road")))
    # in radiance (before the camera's auto-exposure, which a bright mirror image moves for the whole frame)
    np.testing.assert_array_equal(shiny_lin[:, ~floor], matte_lin[:, ~floor])
    assert (np.abs(shiny_lin - matte_lin).max(axis=0)[floor] > 1e-3).mean() > 0.5


def test_reflection_checks_its_parameters():
    for bad in ((0.0, 1.0), (1.5, 1.0), (0.2, -1.0)):
        with pytest.raises(ValueError, match="0 < strength <= 1 and blur_px >= 0"):
            Reflection(*bad)
