"""Back-projection, LiDAR projection (z-buffer) and PLY files, checked against geometry and an independent parser."""
import numpy as np
import pytest

from lipjax.data.sample import Intrinsics
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
