"""LiDAR sweep -> sparse depth: calibration readers of every format, point cloud files, and the projection checked
against the devkit's own formula (P2 @ R0_rect @ Tr_velo_to_cam in homogeneous coordinates) on a generated rig
whose calibration files the tests write in KITTI's text formats."""
import pathlib
import warnings

import numpy as np
import pytest

from lipjax.data.calib import read_calibration, read_kitti_object_calib
from lipjax.data.errors import DatasetError
from lipjax.data.lidar import project_sweep
from lipjax.pointcloud import project_lidar_to_depth, read_point_cloud

H, W = 40, 120
FX, FY, CX, CY = 700.0, 690.0, 60.0, 20.0
K = np.array([[FX, 0, CX], [0, FY, CY], [0, 0, 1]])
# Offsets of the rectified cameras from cam0 (metres): image_2 sits ~6 cm to the left of cam0, as on KITTI, and
# here also a little off in y and z so that every component of t = K^-1 P[:, 3] is exercised.
OFFSETS = {0: [0, 0, 0], 1: [-0.54, 0, 0], 2: [0.06, -0.003, 0.0027], 3: [-0.47, 0.002, 0.003]}
P = {i: K @ np.c_[np.eye(3), t] for i, t in OFFSETS.items()}


def _matrix(k) -> np.ndarray:
    """The 3x3 camera matrix of an Intrinsics."""
    return np.array([[k.fx, 0.0, k.cx], [0.0, k.fy, k.cy], [0.0, 0.0, 1.0]])


def _rotation(ax, ay, az):
    cx, cy, cz, sx, sy, sz = np.cos([ax, ay, az]).tolist() + np.sin([ax, ay, az]).tolist()
    return (np.array([[1, 0, 0], [0, cx, -sx], [0, sx, cx]]) @ np.array([[cy, 0, sy], [0, 1, 0], [-sy, 0, cy]])
            @ np.array([[cz, -sz, 0], [sz, cz, 0], [0, 0, 1]]))


R0 = _rotation(0.01, -0.008, 0.005)  # a rectifying rotation of a few tenths of a degree
# Velodyne x forward, y left, z up -> camera x right, y down, z forward; slightly tilted, 27 cm behind cam0.
TR = np.c_[_rotation(0.02, 0.01, -0.015) @ np.array([[0, -1, 0], [0, 0, -1], [1, 0, 0]]), [0.004, -0.076, -0.27]]


def _pad(m):
    out = np.eye(4)
    out[: m.shape[0], : m.shape[1]] = m
    return out


def _cam_from_velo(camera):
    """Ground truth, built from the rig's parts (not from any file): [I | t_X] @ R0 @ Tr."""
    return _pad(np.c_[np.eye(3), OFFSETS[camera]]) @ _pad(R0) @ _pad(TR)


def _numbers(m):
    return " ".join(f"{v:.12e}" for v in np.ravel(m))


def write_object_calib(path):
    lines = [f"P{i}: {_numbers(P[i])}" for i in range(4)]
    lines += [f"R0_rect: {_numbers(R0)}", f"Tr_velo_to_cam: {_numbers(TR)}", f"Tr_imu_to_velo: {_numbers(TR)}"]
    path.write_text("\n".join(lines) + "\n\n")
    return path


def write_raw_calib(folder):
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "calib_velo_to_cam.txt").write_text(
        f"calib_time: 15-Mar-2012 11:37:16\nR: {_numbers(TR[:, :3])}\nT: {_numbers(TR[:, 3])}\n"
        "delta_f: 0.000000e+00 0.000000e+00\ndelta_c: 0.000000e+00 0.000000e+00\n")
    lines = ["calib_time: 09-Jan-2012 13:57:47", "corner_dist: 9.950000e-02"]
    for i in range(4):
        lines += [f"S_0{i}: 1.392000e+03 5.120000e+02", f"K_0{i}: {_numbers(K)}", f"D_0{i}: {_numbers(np.zeros(5))}",
                  f"R_0{i}: {_numbers(np.eye(3))}", f"T_0{i}: {_numbers(OFFSETS[i])}",
                  f"S_rect_0{i}: {W:.6e} {H:.6e}", f"R_rect_0{i}: {_numbers(R0 if i == 0 else np.eye(3))}",
                  f"P_rect_0{i}: {_numbers(P[i])}"]
    (folder / "calib_cam_to_cam.txt").write_text("\n".join(lines) + "\n")
    return folder


def test_every_format_gives_the_rigs_intrinsics_and_transform(tmp_path):
    """KITTI object, tracking (no colons, R_rect / Tr_velo_cam), raw (folder or either file), odometry (Tr is
    R0 @ Tr_velo_to_cam), and a rig as text and YAML: one answer, the ground truth, for image_2 by default."""
    obj = write_object_calib(tmp_path / "object.txt")
    (tmp_path / "tracking.txt").write_text("\n".join(
        [f"P{i} {_numbers(P[i])}" for i in range(4)] + [f"R_rect {_numbers(R0)}", f"Tr_velo_cam {_numbers(TR)}"]))
    raw = write_raw_calib(tmp_path / "2011_09_26")
    (tmp_path / "calib.txt").write_text(
        "\n".join([f"P{i}: {_numbers(P[i])}" for i in range(4)] + [f"Tr: {_numbers((_pad(R0) @ _pad(TR))[:3])}"]))
    truth = _cam_from_velo(2)
    (tmp_path / "rig.txt").write_text(f"# my rig\nK: {_numbers(K)}\nT_cam_from_lidar: {_numbers(truth)}\n")
    (tmp_path / "rig.yaml").write_text(f"intrinsics: [{FX}, {FY}, {CX}, {CY}]\nT_cam_from_lidar:\n" + "".join(
        f"  - [{', '.join(repr(float(v)) for v in row)}]\n" for row in truth[:3]))
    for path in (obj, tmp_path / "tracking.txt", raw, raw / "calib_cam_to_cam.txt", raw / "calib_velo_to_cam.txt",
                 tmp_path / "calib.txt", tmp_path / "rig.txt", tmp_path / "rig.yaml"):
        intrinsics, t = read_calibration(path)
        assert (intrinsics.fx, intrinsics.fy, intrinsics.cx, intrinsics.cy) == (FX, FY, CX, CY), path
        np.testing.assert_allclose(t, truth, atol=1e-12, err_msg=str(path))
    for camera in (0, 3):
        np.testing.assert_allclose(read_calibration(obj, camera)[1], _cam_from_velo(camera), atol=1e-12)
        np.testing.assert_allclose(read_calibration(raw, camera)[1], _cam_from_velo(camera), atol=1e-12)


# docs/usage.md's own-rig example, verbatim: numbers spaced in groups, and a "#" comment after each line.
RIG_EXAMPLE = """\
K: 721.5 0 609.6  0 721.5 172.9  0 0 1        # or  intrinsics: fx fy cx cy
T_cam_from_lidar: 0 -1 0 0.06  0 0 -1 -0.08  1 0 0 -0.27    # 3x4 or 4x4, row-major: p_cam = R p_lidar + t
"""


@pytest.mark.parametrize("name", ["rig.txt", "rig.yaml"])
def test_the_docs_rig_example_reads_as_text_and_as_yaml(tmp_path, name):
    """The own-rig calibration of docs/usage.md, written as it stands there into a .txt and a .yaml file: the
    trailing comments are dropped, and YAML's strings of numbers read as the numbers."""
    usage = (pathlib.Path(__file__).parents[1] / "docs" / "usage.md").read_text()
    assert RIG_EXAMPLE in usage, "docs/usage.md's rig example changed: update RIG_EXAMPLE"
    (tmp_path / name).write_text(RIG_EXAMPLE)
    intrinsics, t = read_calibration(tmp_path / name)
    assert (intrinsics.fx, intrinsics.fy, intrinsics.cx, intrinsics.cy) == (721.5, 721.5, 609.6, 172.9)
    expected = [[0, -1, 0, 0.06], [0, 0, -1, -0.08], [1, 0, 0, -0.27], [0, 0, 0, 1]]
    np.testing.assert_array_equal(t, expected)


def _devkit_projection(sweep_path, k, shape, tr=TR):
    """(the (H, W) depth of the nearest point per pixel, 0 elsewhere; the sweep's point count; the points that land
    in the image) by the devkit's formula, u, v, w = P2 @ R0_rect @ Tr_velo_to_cam @ [p; 1] with P2 = k @ [I |
    camera 2's offset], independently of project_sweep."""
    sweep = np.fromfile(sweep_path, np.float32).reshape(-1, 4)
    uvw = k @ np.c_[np.eye(3), OFFSETS[2]] @ _pad(R0) @ _pad(tr) @ np.c_[sweep[:, :3], np.ones(len(sweep))].T
    col, row, w = np.floor(uvw[0] / uvw[2] + 0.5), np.floor(uvw[1] / uvw[2] + 0.5), uvw[2]
    inside = (w > 0) & (col >= 0) & (col < shape[1]) & (row >= 0) & (row < shape[0])
    depth = np.full(shape, np.inf)
    np.minimum.at(depth, (row[inside].astype(int), col[inside].astype(int)), w[inside])
    depth[np.isinf(depth)] = 0
    return depth, len(sweep), int(inside.sum())


def test_projection_agrees_pixel_for_pixel_with_the_devkit_formula(tmp_path):
    """2000 points (some outside the image, some behind, many sharing a pixel) projected by project_sweep from a
    written calib file and a .bin sweep, and independently as u, v, w = P2 @ R0_rect @ Tr_velo_to_cam @ [p; 1]
    with a nearest-w z-buffer: the same pixels, the same depths."""
    rng = np.random.default_rng(0)
    n = 2000
    u, v = rng.uniform(-10, W + 10, n), rng.uniform(-5, H + 5, n)
    z = np.where(rng.random(n) < 0.05, -rng.uniform(1, 5, n), rng.uniform(2, 60, n))  # 5 % behind the camera
    cam2 = np.stack([(u - CX) / FX * z, (v - CY) / FY * z, z, np.ones(n)])
    velo = (np.linalg.inv(_cam_from_velo(2)) @ cam2)[:3].T
    sweep = np.c_[velo, rng.random(n)].astype(np.float32)  # x y z reflectance, as KITTI stores it
    sweep.tofile(tmp_path / "000000.bin")
    sparse, intrinsics = project_sweep(tmp_path / "000000.bin", write_object_calib(tmp_path / "calib.txt"), (H, W))

    expected, _, inside = _devkit_projection(tmp_path / "000000.bin", K, (H, W))
    assert _matrix(intrinsics).tolist() == K.tolist()
    assert 500 < (expected > 0).sum() < inside  # many pixels, and some shared by several points
    np.testing.assert_array_equal(sparse > 0, expected > 0)
    np.testing.assert_allclose(sparse, expected, rtol=1e-6)


def test_a_point_on_image_2s_optical_axis_lands_on_its_principal_point(tmp_path):
    """P2's offset from cam0 is part of the transform: a point 7 m along image_2's optical axis lands on (cy, cx)
    at 7 m; projected with R0_rect @ Tr_velo_to_cam alone (the offset forgotten) it lands 6 px to the left."""
    point = (np.linalg.inv(_cam_from_velo(2)) @ [0, 0, 7.0, 1])[:3]
    np.save(tmp_path / "axis.npy", point[None])
    sparse, _ = project_sweep(tmp_path / "axis.npy", write_object_calib(tmp_path / "calib.txt"), (H, W))
    assert np.argwhere(sparse).tolist() == [[CY, CX]] and sparse[int(CY), int(CX)] == pytest.approx(7.0, abs=1e-5)
    forgotten = project_lidar_to_depth(point[None], K, _pad(R0) @ _pad(TR), (H, W))
    assert np.argwhere(forgotten).tolist() == [[CY, CX - 6]]


def test_point_cloud_files_bin_npy_and_pcd_read_alike(tmp_path):
    """KITTI .bin, .npy with extra columns, and PCD ascii / binary (with other fields around x y z) give the same
    x y z; broken files are one-line errors naming the file."""
    xyzi = np.array([[1.5, -2.25, 0.5, 0.3], [10.0, 3.0, -1.0, 0.9], [np.nan, 0, 0, 0]], np.float32)
    xyzi.tofile(tmp_path / "a.bin")
    np.save(tmp_path / "a.npy", xyzi.astype(np.float64))
    head = ("# .PCD v0.7\nVERSION 0.7\nFIELDS ring x y z intensity\nSIZE 2 4 4 4 4\nTYPE U F F F F\n"
            "COUNT 1 1 1 1 1\nWIDTH 3\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 3\n")
    rows = "".join(f"7 {x} {y} {z} {i}\n" for x, y, z, i in xyzi.tolist())
    (tmp_path / "ascii.pcd").write_text(head + "DATA ascii\n" + rows)
    records = np.zeros(3, [("ring", "<u2"), ("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("i", "<f4")])
    records["x"], records["y"], records["z"], records["i"] = xyzi.T
    (tmp_path / "binary.pcd").write_bytes((head + "DATA binary\n").encode() + records.tobytes())
    for name in ("a.bin", "a.npy", "ascii.pcd", "binary.pcd"):
        np.testing.assert_array_equal(read_point_cloud(tmp_path / name), xyzi[:, :3], err_msg=name)
    xyzi.ravel()[:-1].tofile(tmp_path / "short.bin")  # 11 float32: a point cut short
    (tmp_path / "c.pcd").write_text(head + "DATA binary_compressed\n")
    for name, message in (("short.bin", "not a multiple of 16"), ("c.pcd", "save it as ascii or binary"),
                          ("a.las", "unknown point cloud format")):
        with pytest.raises(ValueError, match=message) as info:
            read_point_cloud(tmp_path / name)
        assert name in str(info.value) and "\n" not in str(info.value)


def test_calibration_mistakes_are_named(tmp_path):
    (tmp_path / "p_only.txt").write_text(f"P2: {_numbers(P[2])}\n")
    (tmp_path / "short.txt").write_text(f"P2: {_numbers(P[2])}\nR0_rect: 1 0 0\nTr_velo_to_cam: {_numbers(TR)}\n")
    (tmp_path / "skew.txt").write_text(
        f"P2: {_numbers(P[2] + [[0, 3, 0, 0], [0, 0, 0, 0], [0, 0, 0, 0]])}\nR0_rect: {_numbers(R0)}\n"
        f"Tr_velo_to_cam: {_numbers(TR)}\n")
    for name, message in (("p_only.txt", "Not a calibration file of a known format"),
                          ("short.txt", "3 numbers in R0_rect"), ("skew.txt", "not a camera matrix"),
                          ("missing.txt", "Calibration file not found")):
        with pytest.raises(DatasetError, match=message):
            read_calibration(tmp_path / name)
    with pytest.raises(DatasetError, match="no P5"):
        read_kitti_object_calib(write_object_calib(tmp_path / "calib.txt"), camera=5)
    np.save(tmp_path / "behind.npy", np.array([[-5.0, 0, 0]]))
    # the counts say why (all behind the camera: the transform's direction, likely)
    with pytest.raises(ValueError, match="none of its 1 points lands in the 120x40 image .*0 of 1 points kept: 0 "
                                         "hidden behind a nearer point on the same pixel, 0 outside the image, 1 "
                                         "behind the camera"):
        project_sweep(tmp_path / "behind.npy", tmp_path / "calib.txt", (H, W))


def test_intrinsics_files_take_calibration_files_and_a_bare_p(tmp_path):
    """`--intrinsics-file` (read_intrinsics_txt): a KITTI calib file (image_2 by default, or --camera), a bare 3x4
    P; 16 numbers are a one-line error that names the accepted contents."""
    from lipjax.data.folder import read_intrinsics_txt

    (tmp_path / "p2.txt").write_text(_numbers(P[2]))
    (tmp_path / "t.txt").write_text(_numbers(np.eye(4)))
    obj = write_object_calib(tmp_path / "calib.txt")
    for path in (obj, tmp_path / "p2.txt"):
        assert _matrix(read_intrinsics_txt(path)).tolist() == K.tolist()
    assert _matrix(read_intrinsics_txt(obj, camera=3)).tolist() == K.tolist()
    with pytest.raises(DatasetError, match="found 16 numbers") as info:
        read_intrinsics_txt(tmp_path / "t.txt")
    assert "calibration file (P2: ..." in str(info.value)


def test_project_command_writes_the_sparse_image(tmp_path, capsys):
    """`lipjax project`: .npy equal to project_sweep's, .png at KITTI's 256 per metre, a one-line summary (none
    with -q); a depth PNG given as the image is a one-line error."""
    import cv2

    from lipjax import cli

    rng = np.random.default_rng(1)
    cam2 = np.stack([rng.uniform(-2, 2, 300), rng.uniform(-0.5, 0.5, 300), rng.uniform(5, 30, 300), np.ones(300)])
    sweep = np.c_[(np.linalg.inv(_cam_from_velo(2)) @ cam2)[:3].T, rng.random(300)].astype(np.float32)
    sweep.tofile(tmp_path / "000000.bin")
    calib = write_object_calib(tmp_path / "calib.txt")
    cv2.imwrite(str(tmp_path / "image.png"), np.full((H, W, 3), 90, np.uint8))
    args = ["project", "--lidar", str(tmp_path / "000000.bin"), "--calib", str(calib), "--rgb",
            str(tmp_path / "image.png")]
    assert cli.main(args + ["--out", str(tmp_path / "sparse.npy")]) == 0
    expected, _, counts = project_sweep(tmp_path / "000000.bin", calib, (H, W), return_counts=True)
    np.testing.assert_array_equal(np.load(tmp_path / "sparse.npy"), expected)
    n = int((expected > 0).sum())
    line = capsys.readouterr().err.strip()
    assert line == (f"wrote {tmp_path / 'sparse.npy'}: depth at {n} pixels ({100 * n / (H * W):.1f} % of {W}x{H}), "
                    f"{expected[expected > 0].min():.2f} to {expected.max():.2f} m; {counts.summary()}")
    # every point of the sweep accounted for: all 300 lie 5-30 m in front of camera 2, so none is behind it
    assert counts.points == 300 and counts.behind == counts.not_finite == 0 and counts.kept == n
    assert counts.kept + counts.hidden + counts.outside == 300 and counts.outside > 0
    assert cli.main(args + ["--out", str(tmp_path / "sparse.png"), "-q"]) == 0
    raw = cv2.imread(str(tmp_path / "sparse.png"), cv2.IMREAD_UNCHANGED)
    assert raw.dtype == np.uint16 and capsys.readouterr().err == ""
    np.testing.assert_array_equal(raw, np.round(expected.astype(np.float64) * 256).astype(np.uint16))
    assert cli.main(args[:-1] + [str(tmp_path / "sparse.png"), "--out", str(tmp_path / "x.npy")]) == 1
    err = capsys.readouterr().err
    assert err.startswith("lipjax: error: A 16-bit single-channel PNG is a depth map") and err.count("\n") == 1


# A spinning LiDAR's sweep (32 beams from +2 to -24.8 degrees, every 0.5 degrees round, 1.73 m above a flat road
# between walls 7 m to the left and 9 m to the right, 8 m high, nothing beyond 80 m) and a camera of 90 degrees on
# the rig above: the geometry of a KITTI street, small.
SH, SW, SF = 48, 160, 80.0
SK = np.array([[SF, 0, (SW - 1) / 2], [0, SF, (SH - 1) / 2], [0, 0, 1]])


def _street_sweep(path):
    elevation, azimuth = np.meshgrid(np.deg2rad(np.linspace(2.0, -24.8, 32)), np.deg2rad(np.arange(0, 360, 0.5)),
                                     indexing="ij")
    rays = np.stack([np.cos(elevation) * np.cos(azimuth), np.cos(elevation) * np.sin(azimuth), np.sin(elevation)],
                    -1).reshape(-1, 3)
    reach = np.full(len(rays), np.inf)
    down = rays[:, 2] < 0
    reach[down] = -1.73 / rays[down, 2]
    for y in (7.0, -9.0):
        side = rays[:, 1] * np.sign(y) > 0
        hit = np.where(side, y / np.where(side, rays[:, 1], 1.0), np.inf)
        wall = side & (hit * rays[:, 2] <= 8.0) & (hit < reach)
        reach[wall] = hit[wall]
    seen = reach < 80
    np.c_[rays[seen] * reach[seen, None], np.full(seen.sum(), 0.5)].astype(np.float32).tofile(path)
    return path


def _street_calib(path, tr=TR, k=SK):
    lines = [f"P{i}: {_numbers(k @ np.c_[np.eye(3), OFFSETS[i]])}" for i in (2, 3)]
    path.write_text("\n".join(lines + [f"R0_rect: {_numbers(R0)}", f"Tr_velo_to_cam: {_numbers(tr)}"]) + "\n")
    return path


def _warnings_of(fn, *args, **kwargs):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        fn(*args, **kwargs)
    return [str(w.message) for w in caught]


def test_a_sweep_with_its_calibration_projects_without_a_warning(tmp_path):
    sweep, calib = _street_sweep(tmp_path / "000000.bin"), _street_calib(tmp_path / "calib.txt")
    assert _warnings_of(project_sweep, sweep, calib, (SH, SW), image_path=tmp_path / "image_2" / "000000.png") == []
    _, _, counts = project_sweep(sweep, calib, (SH, SW), return_counts=True)
    depth, points, _ = _devkit_projection(sweep, SK, (SH, SW))
    assert (counts.points, counts.kept) == (points, np.count_nonzero(depth))
    assert 0.05 < counts.kept / counts.points < 0.2


def test_an_inverted_transform_warns_that_the_points_lie_on_one_side(tmp_path):
    """Issue 55: Tr_velo_to_cam inverted (the camera-to-LiDAR transform given) put 10,513 points of a KITTI sweep in
    the image, completed as "indoor input"; its points lie mostly left of the image's centre (the road turns into
    the image's left half), which warns."""
    sweep = _street_sweep(tmp_path / "000000.bin")
    inverted = np.linalg.inv(_pad(TR))[:3]
    calib = _street_calib(tmp_path / "calib.txt", tr=inverted)
    depth, _, _ = _devkit_projection(sweep, SK, (SH, SW), tr=inverted)
    kept = np.count_nonzero(depth)
    right = np.mean(np.nonzero(depth)[1] > SK[0, 2])  # the share of the kept points right of the principal point
    assert right < 0.25
    assert _warnings_of(project_sweep, sweep, calib, (SH, SW)) == [
        f"{sweep}: only {100 * right:.0f} % of its {kept} points in the image lie in its right half, where a "
        f"calibrated camera sees about half: is the transform in {calib} inverted (camera to LiDAR, not LiDAR to "
        "camera) or another rig's?"]


def test_an_image_of_another_size_than_the_calibrations_warns(tmp_path):
    """A half-size image: the principal point (79.5, 23.5) lies at its corner; one warning names it (the few points
    and their one-sidedness follow from it and are not warned about too). A calibration zoomed in (the principal
    point still central) lands under 2 % of the sweep in the image, which warns."""
    sweep, calib = _street_sweep(tmp_path / "000000.bin"), _street_calib(tmp_path / "calib.txt")
    assert _warnings_of(project_sweep, sweep, calib, (SH // 2, SW // 2)) == [
        f"{calib}: camera 2's principal point (79.5, 23.5) lies far from the centre (39.5, 11.5) of the 80x24 image: "
        "was the image resized or cropped? resize or shift fx, fy, cx, cy with it"]
    zoom_k = SK * [[10], [10], [1]] + [[0, 0, -9 * 79.5], [0, 0, -9 * 23.5], [0, 0, 0]]  # principal point kept
    zoomed = _street_calib(tmp_path / "zoomed.txt", k=zoom_k)
    depth, points, _ = _devkit_projection(sweep, zoom_k, (SH, SW))
    kept = np.count_nonzero(depth)
    assert 0 < kept < 0.02 * points
    assert _warnings_of(project_sweep, sweep, zoomed, (SH, SW)) == [
        f"{sweep}: only {kept} of its {points} points land in the 160x48 image (under 2 %): was the image "
        f"resized or cropped, or is {zoomed} another sweep's calibration?"]


def test_the_camera_named_by_the_images_folder_must_be_the_one_chosen(tmp_path):
    """Issue 55: --camera 3 with an image of image_2 (or the default camera 2 with one of image_3) was accepted
    (P2 and P3 share fx, fy, cx, cy; only the 54 cm baseline differs). The folder of a KITTI image names its camera:
    image_2 (object, odometry), image_02/data (raw); a rig file has one camera and no check."""
    from lipjax.data.lidar import camera_of_image

    assert [camera_of_image(p) for p in ("training/image_2/000000.png", "drive/image_03/data/0000000000.png",
                                         "frames/000000.png", "image_2.png")] == [2, 3, None, None]
    sweep, calib = _street_sweep(tmp_path / "000000.bin"), _street_calib(tmp_path / "calib.txt")
    image = tmp_path / "training" / "image_2" / "000000.png"
    with pytest.raises(ValueError) as info:
        project_sweep(sweep, calib, (SH, SW), camera=3, image_path=image)
    assert str(info.value) == (f"{image}: its folder names KITTI camera 2 (image_2), but camera 3's projection was "
                               f"taken from {calib}: give --camera 2")
    raw = tmp_path / "drive" / "image_03" / "data" / "0000000000.png"
    with pytest.raises(ValueError, match=r"names KITTI camera 3 \(image_3\), but camera 2's .*: give --camera 3$"):
        project_sweep(sweep, calib, (SH, SW), image_path=raw)
    project_sweep(sweep, calib, (SH, SW), camera=3, image_path=raw)
    rig = tmp_path / "rig.txt"
    rig.write_text(f"K: {_numbers(SK)}\nT_cam_from_lidar: {_numbers(_cam_from_velo(2))}\n")
    project_sweep(sweep, rig, (SH, SW), camera=2, image_path=raw)  # one camera: nothing to choose


def test_a_sweep_in_millimetres_is_an_error_naming_the_unit(tmp_path):
    sweep = np.fromfile(_street_sweep(tmp_path / "000000.bin"), np.float32).reshape(-1, 4)[:, :3]
    np.save(tmp_path / "mm.npy", sweep * 1000)
    with pytest.raises(ValueError) as info:
        project_sweep(tmp_path / "mm.npy", _street_calib(tmp_path / "calib.txt"), (SH, SW))
    assert str(info.value) == (f"{tmp_path / 'mm.npy'}: its points in the image lie at a median depth of 9868: not "
                               "metres (millimetres? divide by 1000)")
