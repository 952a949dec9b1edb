"""Sparse samplers: exact counts, determinism keyed by the example id, LiDAR scan lines, noise, spec parser."""
from __future__ import annotations

import dataclasses
import json
import os
import subprocess
import sys

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from lipjax.data import parallax
from lipjax.data.frame import Frame, Intrinsics
from lipjax.data.sampling import (
    BernoulliSampler,
    HolesSampler,
    KeypointSampler,
    LidarSampler,
    Noise,
    Noisy,
    Parallax,
    UniformSampler,
    example_rng,
    sampler_from_spec,
)

K_KITTI = Intrinsics(721.5377, 721.5377, 609.5593, 172.854)
CAMERA_HEIGHT_M = 1.65


def random_frame(id: str = "a", h: int = 60, w: int = 80, hole_fraction: float = 0.3) -> Frame:
    rng = np.random.default_rng(0)  # same pixels for every id: only the id changes
    depth = rng.uniform(0.5, 10.0, (h, w)).astype(np.float32)
    depth[rng.random((h, w)) < hole_fraction] = 0
    return Frame.from_depth(np.zeros((h, w, 3), np.uint8), depth, Intrinsics(80, 80, w / 2, h / 2), id)


def plane_scene(wall_m: float = 60.0, h: int = 375, w: int = 1242) -> Frame:
    """KITTI-like camera 1.65 m above a flat ground, looking level; a wall at wall_m fills the top."""
    v = np.arange(h, dtype=np.float64)[:, None] * np.ones((1, w))
    with np.errstate(divide="ignore"):
        ground = np.where(v > K_KITTI.cy + 0.5, CAMERA_HEIGHT_M * K_KITTI.fy / (v - K_KITTI.cy), np.inf)
    depth = np.minimum(ground, wall_m).astype(np.float32)
    return Frame.from_depth(np.zeros((h, w, 3), np.uint8), depth, K_KITTI, "plane")


def count_scan_lines(sparse: np.ndarray, half_width: int = 20) -> int:
    """Distinct groups of rows hit in a central column strip (lines are near-horizontal there)."""
    w = sparse.shape[1]
    rows = np.flatnonzero((sparse[:, w // 2 - half_width : w // 2 + half_width] > 0).any(axis=1))
    return 0 if rows.size == 0 else 1 + int(np.sum(np.diff(rows) > 1))


def beams_in_view(sampler: LidarSampler, h: int = 375) -> int:
    """Beams whose elevation (relative to the camera's optical axis) falls inside the image rows."""
    top = np.degrees(np.arctan(K_KITTI.cy / K_KITTI.fy))
    bottom = -np.degrees(np.arctan((h - 1 - K_KITTI.cy) / K_KITTI.fy))
    el = sampler.beam_elevations_deg() + sampler.mount_pitch_deg
    return int(np.sum((el < top) & (el > bottom)))


# ---- uniform / bernoulli -------------------------------------------------------------------------------------


def test_uniform_exact_count_valid_pixels_and_values():
    frame = random_frame()
    sparse = UniformSampler(200)(frame)
    assert sparse.dtype == np.float32 and sparse.shape == frame.shape
    assert np.count_nonzero(sparse) == 200
    assert np.all(frame.valid[sparse > 0]) and np.array_equal(sparse[sparse > 0], frame.depth[sparse > 0])


def test_uniform_fewer_valid_than_requested_keeps_all():
    frame = random_frame(h=10, w=10, hole_fraction=0.5)
    sparse = UniformSampler(500)(frame)
    assert np.array_equal(sparse > 0, frame.valid)


def test_uniform_deterministic_per_id_and_seed():
    a, b = random_frame("a"), random_frame("b")  # same pixels, different ids
    s = UniformSampler(100)
    assert np.array_equal(s(a), s(a)) and np.array_equal(s(a, seed=3), s(a, seed=3))
    assert not np.array_equal(s(a) > 0, s(b) > 0)
    assert not np.array_equal(s(a) > 0, s(a, seed=1) > 0)


def test_uniform_independent_of_process_and_hash_seed():
    """The points depend on sha256(seed/id) only: another interpreter with another hash seed agrees."""
    code = (
        "import json, numpy as np\n"
        "from lipjax.data.frame import Frame, Intrinsics\n"
        "from lipjax.data.sampling import UniformSampler\n"
        "s = Frame.from_depth(np.zeros((30, 40, 3), np.uint8), np.ones((30, 40), np.float32), "
        "Intrinsics(1,1,0,0), 'nyu/val/x/1')\n"
        "print(json.dumps(np.flatnonzero(UniformSampler(25)(s, seed=7)).tolist()))\n"
    )
    env = {**os.environ, "PYTHONHASHSEED": "12345"}
    result = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True)
    here = Frame.from_depth(np.zeros((30, 40, 3), np.uint8), np.ones((30, 40), np.float32), Intrinsics(1, 1, 0, 0),
                            "nyu/val/x/1")
    assert json.loads(result.stdout) == np.flatnonzero(UniformSampler(25)(here, seed=7)).tolist()


def test_example_rng_streams_differ():
    assert example_rng(0, "x").random() == example_rng(0, "x").random()
    assert example_rng(0, "x").random() != example_rng(0, "x", "noise").random()


def test_bernoulli_count_on_average_and_valid_only():
    frame = random_frame(h=200, w=300)
    n_valid = int(frame.valid.sum())
    counts = [np.count_nonzero(BernoulliSampler(500)(frame, seed=s)) for s in range(5)]
    sd = np.sqrt(500 * (1 - 500 / n_valid))
    assert all(abs(c - 500) < 5 * sd for c in counts) and len(set(counts)) > 1
    sparse = BernoulliSampler(500)(frame)
    assert np.all(frame.valid[sparse > 0]) and np.array_equal(sparse, BernoulliSampler(500)(frame))


# ---- LiDAR -----------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("sampler", [LidarSampler(64, (-24.8, 2.0), 0.17), LidarSampler(16, (-15.0, 15.0), 0.2),
                                     LidarSampler.hdl64(), LidarSampler.vlp16(), LidarSampler.vlp32()],
                         ids=["hdl64-no-offset", "vlp16-no-offset", "hdl64", "vlp16", "vlp32"])
def test_lidar_scan_lines_on_a_plane(sampler):
    scene = plane_scene()
    sparse = sampler(scene)
    expected = beams_in_view(sampler)
    assert abs(count_scan_lines(sparse) - expected) <= (0 if sampler.mount_height_m == 0 else 1)
    assert np.all(scene.valid[sparse > 0]) and np.array_equal(sparse[sparse > 0], scene.depth[sparse > 0])
    # About (horizontal field of view / azimuth step) points per line.
    hfov = np.degrees(np.arctan(K_KITTI.cx / K_KITTI.fx) + np.arctan((1241 - K_KITTI.cx) / K_KITTI.fx))
    per_line = np.count_nonzero(sparse) / expected
    assert 0.85 * hfov / sampler.azimuth_step_deg <= per_line <= 1.02 * hfov / sampler.azimuth_step_deg


def test_lidar_one_point_per_cell_and_nearest_to_beam():
    scene = plane_scene()
    sampler = LidarSampler(64, (-24.8, 2.0), 0.17)
    sparse = sampler(scene)
    idx, el, az, _ = sampler.angles(scene)
    chosen = np.isin(idx, np.flatnonzero(sparse.reshape(-1)))
    beams = np.radians(sampler.beam_elevations_deg())
    spacing = beams[1] - beams[0]
    beam = np.rint((el - beams[0]) / spacing).astype(int)
    cells = beam[chosen] * 100000 + np.rint(az[chosen] / np.radians(0.17)).astype(int)
    assert len(np.unique(cells)) == chosen.sum()  # at most one point per (beam, azimuth) cell
    # Chosen points sit much closer to their beam than a random pixel of the band (which averages spacing/4).
    assert np.mean(np.abs(el[chosen] - beams[beam[chosen]])) < spacing / 8


def test_lidar_pitch_and_range():
    scene = plane_scene()
    tilted = LidarSampler(16, (-15.0, 15.0), 0.2, mount_pitch_deg=-6.0)  # tilted down: more beams see the image
    assert count_scan_lines(tilted(scene)) == beams_in_view(tilted) != beams_in_view(LidarSampler(16, (-15.0, 15.0)))
    short = LidarSampler(64, (-24.8, 2.0), 0.17, max_range_m=50.0)
    sparse = short(scene)
    assert sparse.max() <= 50.0 and not np.any(sparse == 60.0)


def test_lidar_dropout_is_deterministic():
    scene = plane_scene()
    full = np.count_nonzero(LidarSampler.vlp16()(scene))
    sampler = LidarSampler.vlp16(dropout=0.5)
    a, b = sampler(scene, seed=1), sampler(scene, seed=1)
    assert np.array_equal(a, b) and 0.4 * full < np.count_nonzero(a) < 0.6 * full
    assert not np.array_equal(a, sampler(scene, seed=2))


# ---- noise -----------------------------------------------------------------------------------------------------


def test_noise_statistics_support_and_determinism():
    frame = random_frame(h=200, w=300)
    clean = UniformSampler(5000)(frame)
    noisy = Noise(std_m=0.1)(clean, frame, seed=0)
    support = clean > 0
    assert np.array_equal(noisy > 0, support)
    assert np.std(noisy[support] - clean[support]) == pytest.approx(0.1, rel=0.05)
    assert np.array_equal(noisy, Noise(std_m=0.1)(clean, frame, seed=0))
    rel = Noise(relative_std=0.05)(clean, frame)
    ratio = (rel[support] - clean[support]) / clean[support]
    assert np.std(ratio) == pytest.approx(0.05, rel=0.05)


def test_noise_outliers_exact_fraction_and_positive():
    frame = random_frame(h=100, w=100)
    clean = UniformSampler(1000)(frame)
    noisy = Noise(outlier_fraction=0.1, outlier_range_m=(20.0, 30.0))(clean, frame)
    changed = noisy != clean
    assert changed.sum() == 100 and np.all((noisy[changed] >= 20) & (noisy[changed] <= 30))
    huge = Noise(std_m=50.0)(clean, frame)
    assert np.array_equal(huge > 0, clean > 0) and huge[clean > 0].min() >= 1e-3


def test_noisy_wrapper_is_its_noise_applied_to_its_samplers_samples():
    frame = random_frame()
    s = Noisy(UniformSampler(50), Noise(std_m=0.2))
    out, clean = s(frame, seed=4), UniformSampler(50)(frame, seed=4)
    assert np.array_equal(out, Noise(std_m=0.2)(clean, frame, 4))  # the same seed for both stages
    assert np.array_equal(out > 0, clean > 0) and not np.array_equal(out, clean)


# ---- spec parser -----------------------------------------------------------------------------------------------


def test_sampler_from_spec():
    assert sampler_from_spec("uniform:200") == UniformSampler(200)
    assert sampler_from_spec("bernoulli:500") == BernoulliSampler(500)
    assert sampler_from_spec("lidar:hdl64") == LidarSampler.hdl64()
    assert sampler_from_spec("lidar:vlp16") == LidarSampler.vlp16()
    s = sampler_from_spec("lidar:vlp32,azimuth_step_deg=0.4+noise:std=0.02,rel=0.01,outliers=0.05")
    assert s == Noisy(dataclasses.replace(LidarSampler.vlp32(), azimuth_step_deg=0.4), Noise(0.02, 0.01, 0.05))
    assert sampler_from_spec("keypoint:500") == KeypointSampler(500)
    assert sampler_from_spec("holes:0.3") == HolesSampler(0.3)
    s = sampler_from_spec("lidar:hdl64+parallax:min_m=0.05,max_m=0.2+noise:rel=0.01")
    assert s == Noisy(Parallax(LidarSampler.hdl64(), 0.05, 0.2), Noise(relative_std=0.01))
    for bad in ("uniform:abc", "lidar:hdl99", "lidar:vlp16,color=1", "gauss:3", "uniform:3+noise:foo=1",
                "uniform:3+blur:1", "holes:1.5", "holes:x", "keypoint:many", "uniform:3+parallax:b=1",
                "uniform:3+parallax:min_m=0.3,max_m=0.1", "uniform:3+parallax:min_m=0",
                "keypoint:-1"):
        with pytest.raises(ValueError):
            sampler_from_spec(bad)


@settings(max_examples=40, deadline=None)
@given(st.integers(0, 300), st.floats(0.0, 1.0), st.integers(0, 2**31 - 1))
def test_uniform_count_is_min_of_n_and_valid(n, hole_fraction, seed):
    frame = random_frame(h=12, w=15, hole_fraction=hole_fraction)
    sparse = UniformSampler(n)(frame, seed=seed)
    assert np.count_nonzero(sparse) == min(n, int(frame.valid.sum()))
    assert np.all(frame.valid[sparse > 0])


# ---- keypoints / holes ---------------------------------------------------------------------------------------


def _half_textured(h: int = 64, w: int = 96) -> Frame:
    """A checkerboard of 8 px squares on the left half of the image, plain grey on the right; depth 2-5 m."""
    rgb = np.full((h, w, 3), 128, np.uint8)
    yy, xx = np.mgrid[0:h, 0 : w // 2]
    rgb[:, : w // 2] = np.where(((yy // 8 + xx // 8) % 2 == 0)[..., None], 30, 220)
    depth = np.linspace(2.0, 5.0, w, dtype=np.float32)[None].repeat(h, 0)
    return Frame.from_depth(rgb, depth, Intrinsics(80, 80, w / 2, h / 2), "half")


def test_keypoints_lie_on_corners_of_valid_pixels_with_their_depth():
    """All 35 inner corners of the checkerboard and nothing on the plain half, at most N, with their depth;
    pixels without depth give no point; the same points for the same (seed, id)."""
    s = _half_textured()
    out = KeypointSampler(40)(s, 0)
    rows, cols = np.nonzero(out)
    assert rows.size <= 40 and (cols <= 48).all()  # on the board or its border with the plain half, never inside it
    np.testing.assert_array_equal(out[rows, cols], s.depth[rows, cols])
    inner = {(r, c) for r in range(8, 64, 8) for c in range(8, 48, 8)}  # where four squares meet: 7 x 5
    assert inner <= set(zip(rows.tolist(), cols.tolist()))
    np.testing.assert_array_equal(out, KeypointSampler(40)(s, 0))
    holed = Frame.from_depth(s.rgb, np.where(np.arange(96)[None] < 24, 0, s.depth), s.intrinsics, "half")
    assert not KeypointSampler(40)(holed, 0)[:, :24].any()
    plain = Frame.from_depth(np.full_like(s.rgb, 128), s.depth, s.intrinsics, "plain")
    assert not KeypointSampler(40)(plain, 0).any()


def test_holes_keep_the_depth_but_not_occlusion_edges_and_cover_the_fraction():
    """Two planes (2 m left, 6 m right): the pixels on both sides of the step are dropped, every kept pixel has its
    ground-truth depth, and the blobs take `fraction` of the frame (a quantile of the field); 0: only the edge."""
    h, w = 80, 100
    depth = np.where(np.arange(w)[None] < 50, 2.0, 6.0).astype(np.float32).repeat(h, 0)
    s = Frame.from_depth(np.zeros((h, w, 3), np.uint8), depth, Intrinsics(80, 80, w / 2, h / 2), "step")
    only_edges = HolesSampler(0.0)(s, 0)
    assert not only_edges[:, 49:51].any() and (only_edges[:, :49] == 2.0).all() and (only_edges[:, 51:] == 6.0).all()
    for fraction in (0.2, 0.5):
        out = HolesSampler(fraction)(s, 0)
        kept = out > 0
        np.testing.assert_array_equal(out[kept], depth[kept])
        assert not kept[:, 49:51].any()
        assert abs((1 - kept.mean()) - (fraction + 2 / w * (1 - fraction))) < 0.03
    np.testing.assert_array_equal(HolesSampler(0.3)(s, 0), HolesSampler(0.3)(s, 0))
    assert not np.array_equal(HolesSampler(0.3)(s, 0), HolesSampler(0.3)(s, 1))


# ---- parallax (lipjax.data.parallax) -----------------------------------------------------------------------------

# A 2 m box (rows 15-30, columns 20-39) before an 8 m wall; fx = 100 px and a 0.16 m baseline along +x shift the
# box by fx b / z = 8 px in the sensor's view and the wall by 2 px, both to the left.
K_BOX = Intrinsics(100.0, 100.0, 31.0, 23.0)
BOX_NEAR_M, WALL_M, BASELINE_M = 2.0, 8.0, (0.16, 0.0, 0.0)


def box_scene() -> np.ndarray:
    depth = np.full((48, 64), WALL_M, np.float32)
    depth[15:31, 20:40] = BOX_NEAR_M
    return depth


def test_sensor_view_of_a_box_shifts_by_disparity_and_continues_the_wall():
    depth = box_scene()
    view = parallax.sensor_view(depth, depth > 0, K_BOX, BASELINE_M)
    expected = np.full_like(depth, WALL_M)
    expected[15:31, 12:32] = BOX_NEAR_M  # box columns 20-39 less 8 px; its old right edge uncovers 32-37 (wall)
    assert np.array_equal(view, expected)


def test_returns_seen_past_the_box_edge_land_on_the_box_with_the_walls_depth():
    depth = box_scene()
    view = parallax.sensor_view(depth, depth > 0, K_BOX, BASELINE_M)
    returns = np.zeros_like(view)
    returns[:, 32:38] = view[:, 32:38]  # the sensor's returns from the uncovered strip only
    camera = parallax.to_camera(returns, K_BOX, BASELINE_M)
    rows, cols = np.nonzero(camera)
    # wall points (8 m) seen through: the box's right 6 columns (34-39 = 32-37 + 2 px) in its rows; the strip's
    # rows above and below the box are wall seen as wall
    assert set(cols) == set(range(34, 40)) and np.all(camera[rows, cols] == WALL_M)
    assert np.all(depth[15:31, 34:40] == BOX_NEAR_M) and np.all(camera[15:31, 34:40] == WALL_M)


def test_sensor_shadow_and_zero_baseline():
    depth = box_scene()
    dense = parallax.to_camera(parallax.sensor_view(depth, depth > 0, K_BOX, BASELINE_M), K_BOX, BASELINE_M)
    # the wall just left of the box (columns 14-19) is hidden from the sensor: no return; so are the camera's two
    # leftmost columns (outside the sensor's view); every other pixel returns the camera's own depth (the box
    # hides the wall seen past its edge: the nearer return wins)
    assert not dense[15:31, 14:20].any() and dense[15:31, 12:14].all() and not dense[:, :2].any()
    seen = dense > 0
    assert np.array_equal(dense[seen], depth[seen]) and seen.sum() == 48 * 62 - 16 * 6
    frame = Frame.from_depth(np.zeros((48, 64, 3), np.uint8), box_scene(), K_BOX, "box")
    assert np.array_equal(parallax.sensor_view(frame.depth, frame.valid, K_BOX, np.zeros(3)), frame.depth)


def test_sensor_view_gives_no_return_where_the_camera_saw_nothing():
    depth = box_scene()
    depth[:10] = 0  # sky above row 10
    view = parallax.sensor_view(depth, depth > 0, K_BOX, BASELINE_M)
    expected = np.full_like(depth, WALL_M)
    expected[15:31, 12:32] = BOX_NEAR_M
    assert not view[:10].any() and np.array_equal(view[10:], expected[10:])


def test_parallax_sampler_is_keyed_by_example_and_its_baseline_in_range():
    frame = random_frame(h=48, w=64, hole_fraction=0.0)
    sampler = Parallax(UniformSampler(300), min_m=0.05, max_m=0.1)
    lengths = [np.linalg.norm(sampler.baseline_m(random_frame(id=str(i)), 3)) for i in range(200)]
    assert 0.05 <= min(lengths) and max(lengths) <= 0.1 and np.median(lengths) == pytest.approx(0.0707, rel=0.1)
    out = sampler(frame, seed=3)
    assert np.array_equal(out, sampler(frame, seed=3)) and not np.array_equal(out, sampler(frame, seed=4))
    # tiny baseline: the same points as the plain sampler, at the camera's depth
    tiny = Parallax(UniformSampler(300), min_m=1e-6, max_m=1e-6)(frame, seed=3)
    assert np.array_equal(tiny, UniformSampler(300)(frame, seed=3))
    rig = Parallax.at(UniformSampler(300), (0.06, -0.08, -0.27))
    assert np.allclose(rig.baseline_m(frame, 3), (0.06, -0.08, -0.27)) and np.allclose(rig.baseline_m(frame, 9),
                                                                                      (0.06, -0.08, -0.27))
    for bad in ((0, 0, 0), (1, 2)):
        with pytest.raises(ValueError):
            Parallax.at(UniformSampler(3), bad)


def test_sensor_behind_the_camera_sees_a_wall_farther_and_its_returns_come_back_exact():
    depth = np.full((48, 64), 4.0, np.float32)
    behind = (0.0, 0.0, -0.5)  # half a metre behind: the view shrinks to the centre; the rim is filled radially
    view = parallax.sensor_view(depth, depth > 0, K_BOX, behind)
    assert np.all(view == 4.5)
    back = parallax.to_camera(view, K_BOX, behind)
    # the sensor's pixels, 4.5 m from it, land 4.5/4 camera pixels apart: they cover (4/4.5)^2 of the camera's grid
    # (measured 0.779 against 0.790: pixels that round onto the same camera pixel)
    assert np.all(back[back > 0] == 4.0) and (back > 0).mean() == pytest.approx((4 / 4.5) ** 2, abs=0.02)
