"""Named evaluation protocols: sizes, exact crop offsets, nearest depth, intrinsics, TartanAir split."""
from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from lipjax.data.protocols import (
    PROTOCOLS,
    BottomCrop,
    CenterCrop,
    EvalProtocol,
    Resize,
    get_protocol,
    nearest_indices,
    tartanair_split,
)
from lipjax.data.frame import Frame, Intrinsics
from lipjax.metrics import evaluation_mask

K_NYU = Intrinsics(518.8579, 519.46961, 325.58245, 253.73617)
K_KITTI = Intrinsics(721.5377, 721.5377, 609.5593, 172.854)


def index_frame(h: int, w: int, k: Intrinsics, holes: bool = False) -> Frame:
    """Depth = 1 + flat pixel index (exact in float32), so every output pixel names its source pixel."""
    depth = (1 + np.arange(h * w, dtype=np.float64)).reshape(h, w).astype(np.float32)
    if holes:
        depth[np.random.default_rng(0).random((h, w)) < 0.4] = 0
    rgb = np.random.default_rng(1).integers(0, 256, (h, w, 3), dtype=np.uint8)
    return Frame.from_depth(rgb, depth, k, "test/index")


def source_pixels(out: Frame, w_in: int) -> tuple[np.ndarray, np.ndarray]:
    flat = out.depth.astype(np.int64) - 1
    return np.divmod(flat, w_in)


def test_registry_names_and_sizes():
    expected = {
        "nyu_paper": ((480, 640), (256, 320)),
        "nyu_ma": ((480, 640), (228, 304)),
        "kitti_paper": ((375, 1242), (256, 1216)),
        "kitti_selection": ((352, 1216), (352, 1216)),
        "tartanair": ((480, 640), (256, 320)),
        "synthetic_indoor": ((256, 320), (256, 320)),
        "synthetic_outdoor": ((256, 320), (256, 320)),
    }
    assert set(expected) <= set(PROTOCOLS)
    for name, (in_size, out_size) in expected.items():
        p = get_protocol(name)
        assert p.name == name and p.output_size == out_size
        out = p(index_frame(*in_size, K_NYU))
        assert out.shape == out_size and out.rgb.shape == (*out_size, 3) and out.id == "test/index"
    with pytest.raises(KeyError, match="known"):
        get_protocol("nope")


def test_depth_ranges():
    assert PROTOCOLS["nyu_paper"].max_depth_m == 10.0 and PROTOCOLS["nyu_ma"].max_depth_m == 10.0
    assert PROTOCOLS["kitti_paper"].max_depth_m == 80.0
    assert PROTOCOLS["kitti_selection"].max_depth_m == math.inf
    p = PROTOCOLS["nyu_paper"]
    mask = evaluation_mask(np.array([0.0, 5.0, 10.0, 10.5]), np.array([True, True, True, False]),
                           min_depth_m=p.min_depth_m, max_depth_m=p.max_depth_m)
    assert mask.tolist() == [False, True, True, False]


def test_nyu_paper_exact_window_and_intrinsics():
    out = PROTOCOLS["nyu_paper"](index_frame(480, 640, K_NYU))
    rows, cols = source_pixels(out, 640)
    # Centre crop 464x580 (rows 8.., cols 30..) then nearest with scale 464/256 = 580/320.
    s = 464 / 256
    assert np.array_equal(rows[:, 0], 8 + np.floor((np.arange(256) + 0.5) * s).astype(int))
    assert np.array_equal(cols[0], 30 + np.floor((np.arange(320) + 0.5) * s).astype(int))
    assert rows.min() >= 8 and rows.max() <= 471 and cols.min() >= 30 and cols.max() <= 609
    k = out.intrinsics
    assert k.fx == pytest.approx(K_NYU.fx / s) and k.fy == pytest.approx(K_NYU.fy / s)
    assert (k.cx == pytest.approx((K_NYU.cx - 30 + 0.5) / s - 0.5)
            and k.cy == pytest.approx((K_NYU.cy - 8 + 0.5) / s - 0.5))


@pytest.mark.parametrize("name,in_size,k", [("nyu_paper", (480, 640), K_NYU), ("nyu_ma", (480, 640), K_NYU),
                                             ("tartanair", (480, 640), Intrinsics(320, 320, 320, 240)),
                                             ("kitti_paper", (375, 1242), K_KITTI)])
def test_nearest_depth_is_consistent_with_intrinsics(name, in_size, k):
    """The source pixel of each output pixel lies on (almost) the same camera ray as the output pixel."""
    out = PROTOCOLS[name](index_frame(*in_size, k))
    rows, cols = source_pixels(out, in_size[1])
    v, u = np.mgrid[0 : out.shape[0], 0 : out.shape[1]]
    ko = out.intrinsics
    ray_out_x, ray_out_y = (u - ko.cx) / ko.fx, (v - ko.cy) / ko.fy
    ray_in_x, ray_in_y = (cols - k.cx) / k.fx, (rows - k.cy) / k.fy
    # Nearest picks a source pixel within half an output pixel of the exact location.
    assert np.abs(ray_out_x - ray_in_x).max() <= 0.5 / ko.fx + 1e-9
    assert np.abs(ray_out_y - ray_in_y).max() <= 0.5 / ko.fy + 1e-9


def test_nyu_ma_offsets():
    out = PROTOCOLS["nyu_ma"](index_frame(480, 640, K_NYU))
    rows, cols = source_pixels(out, 640)
    # Resize x0.5 (output i samples 2i + 1), then crop rows 6.., cols 8..
    assert rows[0, 0] == 2 * 6 + 1 and cols[0, 0] == 2 * 8 + 1
    assert out.intrinsics.fx == pytest.approx(K_NYU.fx / 2)
    assert out.intrinsics.cx == pytest.approx((K_NYU.cx + 0.5) / 2 - 0.5 - 8)


@pytest.mark.parametrize("in_size,top,left", [((375, 1242), 119, 13), ((370, 1226), 114, 5), ((376, 1241), 120, 12)])
def test_kitti_paper_bottom_crop(in_size, top, left):
    frame = index_frame(*in_size, K_KITTI)
    out = PROTOCOLS["kitti_paper"](frame)
    assert np.array_equal(out.depth, frame.depth[top:, left : left + 1216])
    assert np.array_equal(out.rgb, frame.rgb[top:, left : left + 1216])
    assert out.intrinsics == Intrinsics(K_KITTI.fx, K_KITTI.fy, K_KITTI.cx - left, K_KITTI.cy - top)


def test_kitti_selection_is_identity_on_selection_frames_and_crops_full_frames():
    sel = index_frame(352, 1216, K_KITTI)
    assert np.array_equal(PROTOCOLS["kitti_selection"](sel).depth, sel.depth)
    full = index_frame(375, 1242, K_KITTI)
    assert np.array_equal(PROTOCOLS["kitti_selection"](full).depth, full.depth[23:, 13:1229])


def test_no_mixing_of_valid_and_invalid():
    frame = index_frame(480, 640, K_NYU, holes=True)
    for name in ("nyu_paper", "nyu_ma", "tartanair"):
        out = PROTOCOLS[name](frame)
        assert np.array_equal(out.valid, out.depth > 0)
        assert np.all(np.isin(out.depth[out.valid], frame.depth[frame.valid]))  # every value is a real pixel


def test_rgb_uses_area_interpolation_when_shrinking():
    rgb = np.zeros((480, 640, 3), np.uint8)
    rgb[:, 1::2] = 200  # alternate columns: area averages to 100, nearest would give 0 or 200
    frame = Frame.from_depth(rgb, np.ones((480, 640), np.float32), K_NYU, "x")
    out = PROTOCOLS["nyu_ma"](frame)
    assert np.all(np.abs(out.rgb.astype(int) - 100) <= 1)


def test_apply_to_depth_matches_frame_geometry():
    frame = index_frame(375, 1242, K_KITTI, holes=True)
    for name in ("kitti_paper", "nyu_ma"):
        p = PROTOCOLS[name]
        if name == "nyu_ma":
            frame = index_frame(480, 640, K_NYU, holes=True)
        assert np.array_equal(p.apply_to_depth(frame.depth), p(frame).depth)
    assert get_protocol("nyu_ma")(frame).shape == (228, 304)


def test_steps_errors_and_nearest_indices():
    with pytest.raises(ValueError, match="at least"):
        CenterCrop(500, 640).apply(index_frame(480, 640, K_NYU))
    with pytest.raises(ValueError, match="expected"):
        EvalProtocol("bad", (BottomCrop(10, 10),), (20, 20), 0, 1)(index_frame(30, 30, K_NYU))
    assert nearest_indices(4, 2).tolist() == [1, 3]
    assert nearest_indices(3, 6).tolist() == [0, 0, 1, 1, 2, 2]
    assert Resize(5, 5).apply(index_frame(5, 5, K_NYU)).intrinsics == K_NYU


def test_tartanair_split_by_trajectory():
    names = [f"env{e}/{d}/P{p:03d}" for e in range(5) for d in ("Easy", "Hard") for p in range(4)]  # 40
    split = tartanair_split(names)
    counts = {s: sum(v == s for v in split.values()) for s in ("train", "val", "test")}
    assert counts == {"train": 36, "val": 2, "test": 2}
    assert tartanair_split(list(reversed(names))) == split  # independent of listing order
    assert tartanair_split(names, salt="other") != split
    # Weighted by frames: the train share of frames is as close to 90 % as whole trajectories allow.
    frames = [100 + 37 * i % 211 for i in range(len(names))]
    weighted = tartanair_split(names, frames)
    train_frames = sum(f for n, f in zip(names, frames) if weighted[n] == "train")
    assert abs(train_frames / sum(frames) - 0.9) <= max(frames) / sum(frames)
    with pytest.raises(ValueError, match="unique"):
        tartanair_split(["a", "a"])


@settings(max_examples=60, deadline=None)
@given(st.integers(1, 700), st.integers(1, 700))
def test_nearest_indices_pick_the_pixel_under_each_output_centre(in_size, out_size):
    idx = nearest_indices(in_size, out_size)
    assert idx.shape == (out_size,) and idx.min() >= 0 and idx.max() <= in_size - 1 and np.all(np.diff(idx) >= 0)
    centre = (np.arange(out_size) + 0.5) * in_size / out_size  # continuous coordinate, pixel edges at integers
    assert np.all((idx <= centre + 1e-9) & (centre <= idx + 1 + 1e-9))
