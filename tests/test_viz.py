"""Depth and error colour maps use fixed ranges; panels tile images; figures are written."""
import cv2
import matplotlib
import numpy as np
import pytest

from lipjax import viz


def _cmap_end(name, t):
    return np.round(np.asarray(matplotlib.colormaps[name](t)[:3]) * 255).astype(np.uint8)


def test_colorize_depth_fixed_range_and_black_invalid():
    depth = np.array([[0.0, 1.0, 10.0, 25.0], [np.nan, 5.0, -1.0, 1.0]], np.float32)
    img = viz.colorize_depth(depth, 1.0, 10.0, cmap="turbo")
    assert img.shape == (2, 4, 3) and img.dtype == np.uint8
    np.testing.assert_array_equal(img[0, 0], 0)          # 0 = no depth
    np.testing.assert_array_equal(img[1, 0], 0)          # NaN
    np.testing.assert_array_equal(img[1, 2], 0)          # negative
    np.testing.assert_array_equal(img[0, 1], _cmap_end("turbo", 0.0))  # min_m -> low end
    np.testing.assert_array_equal(img[0, 2], _cmap_end("turbo", 1.0))  # max_m -> high end
    np.testing.assert_array_equal(img[0, 3], img[0, 2])  # clipped above the range
    # The range does not adapt to the image: 5 m has the same colour in any picture.
    np.testing.assert_array_equal(viz.colorize_depth(np.full((1, 1), 5.0), 1.0, 10.0)[0, 0], img[1, 1])


def test_error_map_blue_to_red_and_black_without_ground_truth():
    gt = np.array([[2.0, 2.0, 2.0, 0.0]])
    pred = np.array([[2.0, 2.25, 5.0, 3.0]])
    img = viz.error_map(pred, gt, max_error_m=0.5)
    np.testing.assert_array_equal(img[0, 0], _cmap_end("jet", 0.0))   # no error: dark blue
    np.testing.assert_array_equal(img[0, 2], _cmap_end("jet", 1.0))   # >= max error: dark red
    assert img[0, 0, 2] > img[0, 0, 0] and img[0, 2, 0] > img[0, 2, 2]
    np.testing.assert_array_equal(img[0, 3], 0)
    valid = np.array([[True, False, True, True]])
    np.testing.assert_array_equal(viz.error_map(pred, gt, valid, 0.5)[0, 1], 0)


def test_colorize_sparse_enlarges_points_nearest_on_top():
    sparse = np.zeros((9, 9), np.float32)
    sparse[4, 4], sparse[4, 5] = 8.0, 2.0
    img = viz.colorize_sparse(sparse, 0, 10, radius=1)
    near = viz.colorize_depth(np.full((1, 1), 2.0), 0, 10)[0, 0]
    np.testing.assert_array_equal(img[4, 4], near)  # the overlap shows the nearer sample
    assert (img.reshape(-1, 3).any(axis=1)).sum() == 3 * 4  # two 3x3 squares, overlapping in 2 columns
    np.testing.assert_array_equal(img[0, 0], 0)


def test_panel_tiles_rows_with_titles():
    a = np.zeros((10, 20, 3), np.uint8)
    b = np.full((8, 12), 200, np.uint8)  # grey is accepted and centred in a cell of the column's width
    out = viz.panel([[a, b], [a, a]], titles=["left", "right"], pad=2)
    assert out.dtype == np.uint8 and out.shape[1] == 2 + 20 + 2 + 20 + 2
    assert out.shape[0] > 2 + 10 + 2 + 10 + 2  # plus a title band
    one_row = viz.panel([a, a], pad=0)
    assert one_row.shape == (10, 40, 3)
    with pytest.raises(ValueError, match="uint8"):
        viz.panel([a.astype(np.float32)])


def test_comparison_row_and_figure(tmp_path):
    rng = np.random.default_rng(0)
    gt = rng.uniform(1, 9, (16, 20)).astype(np.float32)
    sparse = np.where(rng.random((16, 20)) < 0.05, gt, 0).astype(np.float32)
    rgb = rng.integers(0, 256, (16, 20, 3), dtype=np.uint8)
    row = viz.comparison_row(rgb, sparse, gt, None, {"A": gt + 0.1, "B": gt}, max_m=10, max_error_m=0.5)
    titles = viz.comparison_titles(["A", "B"])
    assert len(row) == len(titles) == 7 and all(im.shape == (16, 20, 3) for im in row)
    viz.write_png(tmp_path / "grid.png", viz.panel([row], titles))
    assert cv2.imread(str(tmp_path / "grid.png")).shape[2] == 3
    viz.save_panel(tmp_path / "fig.png", [row, row], titles, row_labels=["1", "2"],
                   colorbars=[("depth [m]", 0, 10, "turbo"), ("error [m]", 0, 0.5, "jet")])
    fig = cv2.imread(str(tmp_path / "fig.png"))
    assert fig is not None and fig.shape[1] > fig.shape[0]


def test_fitting_range_is_the_models_unless_the_data_do_not_fit():
    rng = np.random.default_rng(0)
    indoor = rng.uniform(1, 8, (20, 30))
    assert viz.fitting_range(indoor, 10.0) == (0.0, 10.0)                     # fits: the fixed range
    street = np.concatenate([rng.uniform(5, 60, 990), np.full(10, 500.0), [0.0, np.nan, np.inf]])
    assert viz.fitting_range(street, 10.0) == (0.0, pytest.approx(np.percentile(street[:1000], 99)))
    assert viz.fitting_range(street, 10.0)[1] < 500                         # the 1 % outliers do not set it
    assert viz.fitting_range(indoor, 85.0) == (0.0, pytest.approx(np.percentile(indoor, 99)))  # under 85 / 4
    assert viz.fitting_range(np.zeros((4, 4)), 10.0) == (0.0, 10.0)
