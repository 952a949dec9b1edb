"""Back-projection, LiDAR projection (z-buffer) and PLY files, checked against geometry and an independent parser."""
import numpy as np
import pytest

from lipjax.data.frame import Intrinsics
from lipjax.pointcloud import ProjectionCounts, backproject, backproject_rgbd, project_lidar_to_depth, write_ply

H, W = 24, 32
K = Intrinsics(fx=30.0, fy=28.0, cx=15.5, cy=11.0)


def _plane_depth(normal=(0.1, -0.2, 1.0), offset=3.0):
    """z of the plane n . p = offset seen through every pixel: z = offset / (n . ray),
    ray = ((u-cx)/fx, (v-cy)/fy, 1)."""
    v, u = np.mgrid[0:H, 0:W]
    rays = np.stack([(u - K.cx) / K.fx, (v - K.cy) / K.fy, np.ones((H, W))], -1)
    return (offset / (rays @ np.asarray(normal))).astype(np.float32), np.asarray(normal), offset


def _read_ply(path):
    """A small PLY reader written for this test (not lipjax code): header, then binary LE or ASCII vertices."""
    data = path.read_bytes()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    header = data[:end].decode("ascii").splitlines()
    assert header[0] == "ply"
    fmt = header[1].split()[1]
    count = next(int(line.split()[2]) for line in header if line.startswith("element vertex"))
    props = [line.split()[1:] for line in header if line.startswith("property")]
    types = {"float": "<f4", "uchar": "u1"}
    dtype = np.dtype([(name, types[t]) for t, name in props])
    if fmt == "binary_little_endian":
        assert len(data) - end == count * dtype.itemsize
        return np.frombuffer(data, dtype, count=count, offset=end)
    rows = np.loadtxt(data[end:].decode("ascii").splitlines(), ndmin=2)
    out = np.empty(count, dtype)
    for i, name in enumerate(dtype.names):
        out[name] = rows[:, i]
    return out


def test_plane_backprojects_onto_the_plane_and_projects_back_to_the_same_depth():
    depth, normal, offset = _plane_depth()
    depth[3, 5] = 0  # an invalid pixel is skipped
    points = backproject(depth, K)
    assert points.shape == (H * W - 1, 3) and points.dtype == np.float32
    np.testing.assert_allclose(points @ normal, offset, rtol=1e-5)
    back = project_lidar_to_depth(points, K, np.eye(4), (H, W))
    np.testing.assert_allclose(back, depth, rtol=1e-6)
    assert back[3, 5] == 0


def test_camera_axes_x_right_y_down_z_forward():
    depth = np.zeros((H, W), np.float32)
    depth[0, W - 1] = 2.0  # top-right pixel: right of and above the principal point
    (x, y, z), = backproject(depth, K)
    assert x > 0 and y < 0 and z == 2.0
    np.testing.assert_allclose([x, y], [(W - 1 - K.cx) / K.fx * 2, (0 - K.cy) / K.fy * 2], rtol=1e-6)


def test_extrinsics_move_points_into_the_camera_frame():
    depth, _, _ = _plane_depth()
    cam = backproject(depth, K).astype(np.float64)
    # A LiDAR frame rotated 90 degrees about z and shifted: p_cam = R p_lidar + t.
    r = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    t = np.array([0.3, -0.1, 0.2])
    lidar = (cam - t) @ r  # inverse transform: R^T (p - t), row-vector form
    T = np.eye(4)
    T[:3, :3], T[:3, 3] = r, t
    np.testing.assert_allclose(project_lidar_to_depth(lidar, K, T, (H, W)), depth, rtol=1e-5)
    K3 = np.array([[K.fx, 0.0, K.cx], [0.0, K.fy, K.cy], [0.0, 0.0, 1.0]])  # a (3, 3) matrix works as well
    np.testing.assert_allclose(project_lidar_to_depth(lidar, K3, T[:3], (H, W)), depth, rtol=1e-5)


@pytest.mark.parametrize("order", [(0, 1, 2), (2, 1, 0), (1, 2, 0)])
def test_nearest_point_wins_in_a_pixel(order):
    ray = np.array([(7 - K.cx) / K.fx, (4 - K.cy) / K.fy, 1.0])  # through the centre of pixel (row 4, col 7)
    points = np.stack([ray * 5.0, ray * 2.0, ray * 3.5])[list(order)]
    depth = project_lidar_to_depth(points, K, np.eye(4), (H, W))
    assert depth[4, 7] == pytest.approx(2.0)
    assert np.count_nonzero(depth) == 1


def test_points_behind_the_camera_or_outside_the_image_are_dropped():
    points = np.array([
        [0.0, 0.0, -2.0],                                # behind
        [0.0, 0.0, 0.0],                                 # on the camera centre
        [(W + 3 - K.cx) / K.fx * 2, 0.0, 2.0],           # right of the image
        [0.0, (-1 - K.cy) / K.fy * 2, 2.0],              # above the image
        [(3 - K.cx) / K.fx * 4, (5 - K.cy) / K.fy * 4, 4.0],  # pixel (5, 3)
    ])
    depth = project_lidar_to_depth(np.column_stack([points, np.ones(len(points))]), K, np.eye(4), (H, W))
    assert depth.shape == (H, W) and depth.dtype == np.float32
    assert np.count_nonzero(depth) == 1 and depth[5, 3] == pytest.approx(4.0)


def test_counts_say_where_every_point_went():
    """points = not_finite + behind + outside + hidden + kept, each counted on a sweep built to hold a known number."""
    ray = np.array([(7 - K.cx) / K.fx, (4 - K.cy) / K.fy, 1.0])  # through the centre of pixel (row 4, col 7)
    points = np.array([
        [np.nan, 0.0, 2.0],                              # not finite
        [0.0, 0.0, -2.0], [0.0, 0.0, 0.0],               # behind, and on the camera centre
        [(W + 3 - K.cx) / K.fx * 2, 0.0, 2.0],           # right of the image
        ray * 5.0, ray * 2.0, ray * 3.5,                 # one pixel: the nearest kept, two hidden
        [(3 - K.cx) / K.fx * 4, (5 - K.cy) / K.fy * 4, 4.0],  # pixel (5, 3)
    ])
    depth, counts = project_lidar_to_depth(points, K, np.eye(4), (H, W), return_counts=True)
    assert counts == ProjectionCounts(points=8, not_finite=1, behind=2, outside=1, hidden=2, kept=2)
    assert counts.kept == np.count_nonzero(depth) and depth[4, 7] == pytest.approx(2.0)
    assert counts.summary() == ("2 of 8 points kept: 2 hidden behind a nearer point on the same pixel, 1 outside the "
                                "image, 2 behind the camera, 1 not finite")


def test_bad_extrinsics_rejected():
    with pytest.raises(ValueError, match="4x4"):
        project_lidar_to_depth(np.ones((3, 3)), K, np.eye(3), (H, W))


@pytest.mark.parametrize("binary", [True, False])
def test_ply_round_trip(tmp_path, binary):
    depth, _, _ = _plane_depth()
    rgb = np.random.default_rng(0).integers(0, 256, (H, W, 3), dtype=np.uint8)
    points, colors = backproject_rgbd(depth, rgb, K)
    path = tmp_path / "cloud.ply"
    write_ply(path, points, colors, binary=binary)
    v = _read_ply(path)
    assert len(v) == H * W
    np.testing.assert_allclose(np.column_stack([v["x"], v["y"], v["z"]]), points, rtol=1e-5 if not binary else 0)
    np.testing.assert_array_equal(np.column_stack([v["red"], v["green"], v["blue"]]), colors)
    write_ply(path, points[:5], binary=binary)
    v = _read_ply(path)
    assert v.dtype.names == ("x", "y", "z") and len(v) == 5


def _xyzi(n=400, seed=0):
    """A sweep as KITTI stores it: x, y within 40 m, z from 2 m below the sensor to 1 m above, reflectance 0-1."""
    rng = np.random.default_rng(seed)
    return np.c_[rng.uniform(-40, 40, (n, 2)), rng.uniform(-2, 1, n), rng.random(n)].astype(np.float32)


def _bin_fix(path, columns, dtype):
    return (f"save it as a .npy, which records its layout: np.save('{path.with_suffix('.npy')}', "
            f"np.fromfile('{path}', np.{dtype}).reshape(-1, {columns}))")


def test_a_bin_in_another_layout_is_an_error_naming_it_and_its_fix(tmp_path):
    """Issue 55: a float64 .bin, a 3-column one (whose size is or is not a multiple of 16) and a nuScenes one (5
    columns) read as KITTI's float32 x y z reflectance gave garbage; each is now one line naming its layout (and
    why KITTI's does not fit) and how to save it as a .npy. KITTI's own layout reads as before."""
    from lipjax.pointcloud import read_point_cloud

    xyzi = _xyzi()
    xyzi.tofile(tmp_path / "kitti.bin")
    np.testing.assert_array_equal(read_point_cloud(tmp_path / "kitti.bin"), xyzi[:, :3])
    cases = {"f64.bin": (xyzi.astype(np.float64), 4, "float64", "x y z reflectance",
                         "read so, its points lie up to 3.7e+19 m away"),
             "xyz.bin": (xyzi[:, :3], 3, "float32", "x y z",
                         "read so, its reflectances are negative: its points are scrambled"),
             "xyz_odd.bin": (xyzi[:-1, :3], 3, "float32", "x y z", "its 4788 bytes are no multiple of 16"),
             "nuscenes.bin": (np.c_[xyzi, np.full(len(xyzi), 7.0, np.float32)], 5, "float32",
                              "x y z intensity ring, as nuScenes",
                              "read so, its reflectances are negative: its points are scrambled")}
    for name, (table, columns, dtype, what, why) in cases.items():
        path = tmp_path / name
        table.tofile(path)
        with pytest.raises(ValueError) as info:
            read_point_cloud(path)
        assert str(info.value) == (f"{path}: a .bin of {columns} {dtype} per point ({what}), not KITTI's 4 float32 "
                                   f"(x y z reflectance; {why}); {_bin_fix(path, columns, dtype)}"), name
    np.save(tmp_path / "xyz.npy", np.fromfile(tmp_path / "xyz.bin", np.float32).reshape(-1, 3))  # the fix works
    np.testing.assert_array_equal(read_point_cloud(tmp_path / "xyz.npy"), xyzi[:, :3])


def test_a_bin_in_millimetres_or_of_no_known_layout_is_an_error(tmp_path):
    from lipjax.pointcloud import read_point_cloud

    (_xyzi() * 1000).tofile(tmp_path / "mm.bin")
    with pytest.raises(ValueError) as info:
        read_point_cloud(tmp_path / "mm.bin")
    assert str(info.value) == (f"{tmp_path / 'mm.bin'}: read as KITTI's float32 x y z reflectance, 100 % of its "
                               "points lie beyond 1000 m: millimetres? save x y z / 1000 (metres) as an (N, 3) .npy")
    np.full((400, 4), 1e7, np.float32).tofile(tmp_path / "far.bin")
    with pytest.raises(ValueError) as info:
        read_point_cloud(tmp_path / "far.bin")
    assert str(info.value) == (f"{tmp_path / 'far.bin'}: read as KITTI's float32 x y z reflectance, 100 % of its "
                               "points lie beyond 1000 m: not a sweep in metres in any layout lipjax knows; save "
                               "x y z metres as an (N, 3) .npy")


def test_a_kitti_bin_with_missing_returns_or_odd_reflectance_still_reads(tmp_path):
    """NaN points (no return) are left to the projection; a 4th column with negative values, where no other layout
    fits, is a KITTI sweep whose reflectance is odd (it is not used)."""
    from lipjax.pointcloud import read_point_cloud

    xyzi = _xyzi()
    xyzi[::10, :3] = np.nan
    xyzi[:, 3] = -1.0
    xyzi[:-2].tofile(tmp_path / "odd.bin")  # 398 points: no 3-column reading fits their 6368 bytes
    np.testing.assert_array_equal(read_point_cloud(tmp_path / "odd.bin"), xyzi[:-2, :3])
