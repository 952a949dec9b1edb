"""Tests of the procedural RGB-D data set (lipjax.data.synthetic): determinism, splits, the data contract, the
camera model and the geometry of the rendered depth (z-depth on the floor / road plane), at small sizes."""
from __future__ import annotations

import hashlib
import subprocess
import sys

import numpy as np
import pytest

from lipjax.data import synthetic as S
from lipjax.data.frame import Frame, Intrinsics

H, W = 48, 64  # NYU's 3:4 aspect: indoor intrinsics are then an exact isotropic resize


def _digest(s: Frame) -> str:
    h = hashlib.sha256()
    for a in (s.rgb, s.depth, s.valid):
        h.update(np.ascontiguousarray(a).tobytes())
    return h.hexdigest()


@pytest.mark.parametrize("kind", S.SYNTHETIC_KINDS)
def test_same_arguments_give_identical_arrays(kind):
    a = S.render(kind, "val", 3, H, W)
    b = S.render(kind, "val", 3, H, W)
    np.testing.assert_array_equal(a.rgb, b.rgb)
    np.testing.assert_array_equal(a.depth, b.depth)
    np.testing.assert_array_equal(a.valid, b.valid)
    assert a.intrinsics == b.intrinsics and a.id == b.id


def test_identical_in_a_fresh_process():
    """No salted hash() or other per-process state: another interpreter renders the same bytes."""
    code = ("import hashlib, numpy as np; from lipjax.data import synthetic as S\n"
            "for kind in S.SYNTHETIC_KINDS:\n"
            f"    s = S.render(kind, 'test', 7, {H}, {W}); h = hashlib.sha256()\n"
            "    [h.update(np.ascontiguousarray(a).tobytes()) for a in (s.rgb, s.depth, s.valid)]\n"
            "    print(h.hexdigest())\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.split()
    assert out == [_digest(S.render(kind, "test", 7, H, W)) for kind in S.SYNTHETIC_KINDS]


@pytest.mark.parametrize("kind", S.SYNTHETIC_KINDS)
def test_splits_and_indices_give_different_scenes(kind):
    digests = {_digest(S.render(kind, split, i, H, W)) for split in S.SPLITS for i in (0, 1)}
    assert len(digests) == 6
    poses = [S.render_with_info(kind, split, 0, H, W)[1].camera_to_world for split in S.SPLITS]
    assert not np.allclose(poses[0], poses[1]) and not np.allclose(poses[1], poses[2])


@pytest.mark.parametrize("kind", S.SYNTHETIC_KINDS)
def test_sample_contract(kind):
    s = S.render(kind, "train", 12, H, W)
    assert s.rgb.shape == (H, W, 3) and s.rgb.dtype == np.uint8
    assert s.depth.shape == (H, W) and s.depth.dtype == np.float32
    assert s.valid.dtype == np.bool_
    np.testing.assert_array_equal(s.valid, s.depth > 0)
    assert np.isfinite(s.depth).all() and (s.depth >= 0).all()
    assert s.id == f"synthetic/{kind}/train/000012" == S.frame_id(kind, "train", 12)
    assert s.intrinsics == S.intrinsics_for(kind, H, W)
    # a usable image: not black, not blown out, not flat
    assert 15 < s.rgb.mean() < 240 and s.rgb.std() > 8


def test_indoor_depth_range_and_no_invalid_pixels():
    for i in range(4):
        s, info = S.render_with_info("indoor", "val", i, H, W)
        assert s.valid.all(), "the room is closed: every pixel hits a surface"
        assert 0.1 < s.depth.min() and s.depth.max() < 12.0
        assert 0.9 <= info.camera_height_m <= 1.8
        assert not (info.labels == S.LABELS.index("sky")).any()


def test_outdoor_sky_is_invalid_and_depth_within_range():
    sky = S.LABELS.index("sky")
    for i in range(4):
        s, info = S.render_with_info("outdoor", "val", i, H, W)
        assert (info.labels == sky).any(), "some sky is visible"
        assert (s.depth[info.labels == sky] == 0).all()
        assert not s.valid.all()
        d = s.depth[s.valid]
        assert d.size > 0.4 * s.depth.size
        assert 1.0 < d.min() and d.max() <= S.RENDER_FAR_CLIP_M
        assert 1.4 <= info.camera_height_m <= 1.9


def _ground_check(kind: str, label: str, split: str, index: int, height: int, width: int,
                  focal_range=(1.0, 1.0)):
    """Depth of every `label` pixel (a point of the plane y = 0) against the analytic z-depth of that plane.

    Pixel (u, v) looks along d = K^-1 (u, v, 1) in the camera frame (z component 1); its ray meets the plane
    y_world = 0 at t = -c_y / (R d)_y, and because d_z = 1, t is the z-depth."""
    s, info = S.render_with_info(kind, split, index, height, width, focal_range)
    on_plane = info.labels == S.LABELS.index(label)
    k = s.intrinsics
    R, c = info.camera_to_world[:3, :3], info.camera_to_world[:3, 3]
    v, u = np.nonzero(on_plane)
    d_cam = np.stack([(u - k.cx) / k.fx, (v - k.cy) / k.fy, np.ones(u.size)])  # (3, n), float64
    expected = -c[1] / (R[1] @ d_cam)
    # only the part of the plane within range is valid (outdoor: 80 m, like a LiDAR)
    np.testing.assert_array_equal(s.valid[on_plane], expected <= S.RENDER_FAR_CLIP_M)
    mask = on_plane & s.valid
    assert mask.sum() > 50, f"frame {s.id} shows too little {label} for the check"
    keep = expected <= S.RENDER_FAR_CLIP_M
    v, u, d_cam, expected = v[keep], u[keep], d_cam[:, keep], expected[keep]
    depth = s.depth[mask].astype(np.float64)
    np.testing.assert_allclose(depth, expected, rtol=1e-4)
    # equivalently: back-projecting the depth lands on the plane, 1 mm
    world = R @ (d_cam * depth) + c[:, None]
    assert np.abs(world[1]).max() < 1e-3
    # and it is z-depth, not the distance along the ray (those differ off the optical axis)
    ray_length = depth * np.linalg.norm(d_cam, axis=0)
    assert (ray_length - depth).max() > 0.01
    return s, info


@pytest.mark.parametrize("index", [0, 5])
def test_indoor_floor_depth_is_the_analytic_z_depth(index):
    s, info = _ground_check("indoor", "floor", "val", index, H, W)
    assert abs(info.camera_to_world[1, 3] - info.camera_height_m) < 1e-12


def test_outdoor_road_depth_is_the_analytic_z_depth():
    _ground_check("outdoor", "road", "val", 0, 60, 80)


@pytest.mark.parametrize("kind, label, factor", [("indoor", "floor", 0.6), ("outdoor", "road", 1.5)])
def test_a_focal_factor_scales_the_camera_and_the_depth_follows_it(kind, label, factor):
    """focal_range (f, f): the frame's focal lengths are f times the reference, its principal point and pose the
    same, and its floor / road depth is the plane's analytic z-depth through the scaled camera."""
    ref, ref_info = S.render_with_info(kind, "val", 0, 60, 80)
    s, info = _ground_check(kind, label, "val", 0, 60, 80, focal_range=(factor, factor))
    k, k0 = s.intrinsics, ref.intrinsics
    assert (k.fx, k.fy, k.cx, k.cy) == pytest.approx((factor * k0.fx, factor * k0.fy, k0.cx, k0.cy))
    np.testing.assert_array_equal(info.camera_to_world, ref_info.camera_to_world)
    assert not np.array_equal(s.depth, ref.depth)


def test_focal_factors_are_drawn_per_frame_within_the_range_and_reproducibly():
    factors = [S.focal_factor("indoor", "train", i, (0.7, 1.4)) for i in range(200)]
    assert 0.7 <= min(factors) and max(factors) <= 1.4
    assert np.mean(np.log(factors)) == pytest.approx(np.log(0.7 * 1.4) / 2, abs=0.03)  # log-uniform: centred
    assert factors == [S.focal_factor("indoor", "train", i, (0.7, 1.4)) for i in range(200)]
    assert S.focal_factor("indoor", "train", 3) == 1.0
    data = S.SyntheticDataset("indoor", "train", size=2, height=24, width=32, focal_range=(0.7, 1.4))
    assert data[1].intrinsics.fx == pytest.approx(S.intrinsics_for("indoor", 24, 32).fx * factors[1])
    assert "focal_range=(0.7, 1.4)" in repr(data)
    for bad in [(0.0, 1.0), (1.2, 1.1), 1.0, ("a", 1)]:
        with pytest.raises(ValueError, match="focal_range"):
            S.SyntheticDataset("indoor", "train", focal_range=bad)


@pytest.mark.parametrize("kind", S.SYNTHETIC_KINDS)
def test_scene_does_not_depend_on_render_size(kind):
    """At 3x the size, fine pixel (3i + 1, 3j + 1) looks along exactly the ray of coarse pixel (i, j)
    (pixel-centre convention), so the same scene gives the same depth and label there."""
    a, ia = S.render_with_info(kind, "val", 2, H, W)
    b, ib = S.render_with_info(kind, "val", 2, 3 * H, 3 * W)
    np.testing.assert_array_equal(ia.camera_to_world, ib.camera_to_world)
    fine, fine_labels = b.depth[1::3, 1::3], ib.labels[1::3, 1::3]
    same = np.abs(fine - a.depth) <= 1e-4 * np.maximum(a.depth, 1.0)
    assert same.mean() > 0.995  # a few rays grazing an edge may fall either side
    assert (fine_labels == ia.labels).mean() > 0.995


def test_intrinsics_scale_with_size():
    assert S.intrinsics_for("indoor", 480, 640) == S.NYU_INTRINSICS
    assert S.intrinsics_for("outdoor", 375, 1242) == S.KITTI_INTRINSICS
    assert S.intrinsics_for("indoor", 240, 320) == S.NYU_INTRINSICS.resized(0.5, 0.5)
    assert S.intrinsics_for("indoor", H, W) == S.NYU_INTRINSICS.resized(H / 480, W / 640)
    for kind, ref, (h0, w0) in (("indoor", S.NYU_INTRINSICS, S.NYU_IMAGE_SIZE),
                                ("outdoor", S.KITTI_INTRINSICS, S.KITTI_IMAGE_SIZE)):
        for h, w in ((256, 320), (128, 160), (100, 400)):
            k = S.intrinsics_for(kind, h, w)
            assert k.fx / k.fy == pytest.approx(ref.fx / ref.fy, rel=1e-12), "pixels keep their aspect ratio"
            # isotropic scale of the largest centred crop with the render's aspect ratio
            scale = max(h / h0, w / w0)
            assert k.fy == pytest.approx(ref.fy * scale, rel=1e-12)
            # the reference principal point, relative to the crop centre, scales by the same factor
            assert k.cx + 0.5 - w / 2 == pytest.approx((ref.cx + 0.5 - w0 / 2) * scale, rel=1e-9, abs=1e-9)
            assert k.cy + 0.5 - h / 2 == pytest.approx((ref.cy + 0.5 - h0 / 2) * scale, rel=1e-9, abs=1e-9)
    # outdoor at 256x320 keeps KITTI's vertical field of view: fy = 721.5 * 256 / 375
    assert S.intrinsics_for("outdoor", 256, 320).fy == pytest.approx(721.5 * 256 / 375)


def test_invalid_arguments_raise_value_error():
    with pytest.raises(ValueError, match="kind"):
        S.render("underwater", "train", 0, H, W)
    with pytest.raises(ValueError, match="split"):
        S.render("indoor", "training", 0, H, W)
    with pytest.raises(ValueError, match=">= 0"):
        S.render("indoor", "train", -1, H, W)
    with pytest.raises(ValueError):
        S.render("indoor", "train", 1.5, H, W)
    with pytest.raises(ValueError):
        S.render("indoor", "train", 0, 4, W)
    with pytest.raises(ValueError, match="kind"):
        S.SyntheticDataset("underwater", "train")
    with pytest.raises(ValueError, match="split"):
        S.SyntheticDataset("indoor", "dev")
    ds = S.SyntheticDataset("outdoor", "val", size=3, height=H, width=W)
    with pytest.raises(ValueError, match="out of range"):
        ds[3]
    with pytest.raises(IndexError):  # also an IndexError, so sequence idioms stop cleanly
        ds[3]
    with pytest.raises(ValueError, match=">= 0"):
        ds[-1]


def test_dataset():
    assert len(S.SyntheticDataset("indoor", "train")) == S.TRAIN_SIZE == 100_000
    assert len(S.SyntheticDataset("indoor", "val")) == S.VAL_SIZE == 200
    assert len(S.SyntheticDataset("outdoor", "test")) == S.TEST_SIZE == 200
    ds = S.SyntheticDataset("indoor", "test", size=2, height=H, width=W)
    assert len(ds) == 2 and ds.intrinsics == S.intrinsics_for("indoor", H, W)
    items = list(ds)
    assert [s.id for s in items] == ["synthetic/indoor/test/000000", "synthetic/indoor/test/000001"]
    assert _digest(ds[1]) == _digest(items[1]) == _digest(S.render("indoor", "test", 1, H, W))


def test_default_size_is_the_documented_one():
    s = S.render("indoor", "val", 0)
    assert s.shape == (S.DEFAULT_HEIGHT, S.DEFAULT_WIDTH) == (256, 320)
    assert isinstance(s.intrinsics, Intrinsics)


def test_mixed_dataset_interleaves_rooms_and_streets():
    from lipjax.data.synthetic.dataset import MixedSyntheticDataset

    mixed = MixedSyntheticDataset("val", size=4, height=32, width=40)
    assert len(mixed) == 4
    for i in range(4):
        want = S.render(("indoor", "outdoor")[i % 2], "val", i // 2, 32, 40)
        got = mixed[i]
        assert got.id == want.id
        np.testing.assert_array_equal(got.rgb, want.rgb)
        np.testing.assert_array_equal(got.depth, want.depth)
    with pytest.raises(IndexError):
        mixed[4]


def test_a_far_view_replaces_one_rectangle_of_the_room_by_the_same_sized_rectangle_of_the_view():
    """add_far_view: inside the window, rgb and depth are the view's (its invalid sky stays invalid); outside, the
    room's; the window's size and place lie in the documented ranges; the room's id and camera are kept."""
    from lipjax.data.synthetic import far_view as F

    room, view = S.render("indoor", "val", 0, H, W), S.render("outdoor", "val", 0, H, W)
    for seed in range(20):
        t, l, h, w, tv, lv = F.far_view_box((H, W), np.random.default_rng(seed))
        out = F.add_far_view(room, view, np.random.default_rng(seed))
        inside = np.zeros((H, W), bool)
        inside[t:t + h, l:l + w] = True
        assert F.WINDOW_HEIGHT[0] * H - 1 <= h <= F.WINDOW_HEIGHT[1] * H + 1
        assert F.WINDOW_WIDTH[0] * W - 1 <= w <= F.WINDOW_WIDTH[1] * W + 1
        assert 0 <= t <= F.WINDOW_TOP[1] * H and t + h <= H and 0 <= l <= W - w
        assert tv + h <= max(F.VIEW_ROWS * H, h) and 0 <= lv <= W - w
        np.testing.assert_array_equal(out.depth[inside], view.depth[tv:tv + h, lv:lv + w].ravel())
        np.testing.assert_array_equal(out.valid[inside], view.valid[tv:tv + h, lv:lv + w].ravel())
        np.testing.assert_array_equal(out.rgb[inside], view.rgb[tv:tv + h, lv:lv + w].reshape(-1, 3))
        np.testing.assert_array_equal(out.depth[~inside], room.depth[~inside])
        np.testing.assert_array_equal(out.rgb[~inside], room.rgb[~inside])
        assert out.id == room.id and out.intrinsics == room.intrinsics
    with pytest.raises(ValueError, match="view of the room's size"):
        F.add_far_view(room, S.render("outdoor", "val", 0, H, W + 8), np.random.default_rng(0))


def test_mixed_rooms_get_far_views_at_the_given_rate_reproducibly_and_streets_never():
    from lipjax.data.synthetic.dataset import MixedSyntheticDataset, far_view_rng
    from lipjax.data.synthetic.far_view import far_view_box

    closed = MixedSyntheticDataset("train", size=8, height=24, width=32)
    always = MixedSyntheticDataset("train", size=8, height=24, width=32, far_view_prob=1.0)
    assert "far_view_prob=1.0" in repr(always) and "far_view" not in repr(closed)
    for i in range(0, 8, 2):  # room i shows street j through the box, both drawn from room i's stream
        rng = far_view_rng("train", i // 2)
        rng.random()  # the draw that decides whether the room has a view
        view = S.render("outdoor", "train", int(rng.integers(S.TRAIN_SIZE)), 24, 32)
        t, l, h, w, tv, lv = far_view_box((24, 32), rng)
        outside = np.ones((24, 32), bool)
        outside[t:t + h, l:l + w] = False
        np.testing.assert_array_equal(always[i].depth[t:t + h, l:l + w], view.depth[tv:tv + h, lv:lv + w])
        np.testing.assert_array_equal(always[i].depth[outside], closed[i].depth[outside])
        assert _digest(always[i]) == _digest(always[i])
    for i in range(1, 8, 2):
        assert _digest(always[i]) == _digest(closed[i])
    drawn = np.mean([far_view_rng("train", i).random() < 0.3 for i in range(4000)])
    assert abs(drawn - 0.3) < 0.03  # whether room i has a view is the first draw of its stream
    some = MixedSyntheticDataset("train", size=8, height=24, width=32, far_view_prob=0.3)
    for i in range(0, 8, 2):
        has_view = far_view_rng("train", i // 2).random() < 0.3
        assert (_digest(some[i]) != _digest(closed[i])) == has_view
    for bad in (-0.1, 1.5, "x", None):
        with pytest.raises(ValueError, match="far_view_prob must be a probability"):
            MixedSyntheticDataset("train", size=2, height=24, width=32, far_view_prob=bad)
