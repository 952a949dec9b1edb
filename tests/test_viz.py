"""Depth and error colour maps use fixed ranges; panels tile images; figures are written."""
import dataclasses

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


def test_comparison_grid_reads_on_a_laptop_screen(tmp_path, monkeypatch):
    """3 frames x 4 methods (each with its error map) fit a 1400 x 900 screen at 100 %; the error panels are the
    error maps of their predictions, labelled with their RMSE; frames with other methods are an error."""
    from matplotlib.axes import Axes

    shown, texts = [], []
    imshow, text = Axes.imshow, Axes.text

    def recorded_imshow(ax, image, **kwargs):
        shown.append(np.asarray(image))
        return imshow(ax, image, **kwargs)

    def recorded_text(ax, x, y, s, **kwargs):
        texts.append(s)
        return text(ax, x, y, s, **kwargs)

    monkeypatch.setattr(Axes, "imshow", recorded_imshow)
    monkeypatch.setattr(Axes, "text", recorded_text)
    rng = np.random.default_rng(0)
    frames = []
    for i in range(3):
        gt = rng.uniform(1, 9, (32, 40)).astype(np.float32)  # the 4:5 aspect of 256x320
        sparse = np.where(rng.random(gt.shape) < 0.05, gt, 0).astype(np.float32)
        rgb = rng.integers(0, 256, (32, 40, 3), dtype=np.uint8)
        predictions = {name: gt + offset for name, offset in (("A", 0.0), ("B", 0.1), ("C", 0.2), ("linear", 0.4))}
        frames.append(viz.Comparison(f"synthetic/indoor/test/{i:06d}", rgb, sparse, gt, predictions))
    viz.save_comparison_grid(tmp_path / "fig.png", frames, max_m=10, max_error_m=0.5)
    height, width = cv2.imread(str(tmp_path / "fig.png")).shape[:2]
    assert 700 < width <= 1400 and 600 < height <= 900, (width, height)
    # per frame: RGB, sparse, ground truth and the 4 predictions, then the 4 error maps; prediction = gt + offset,
    # so each RMSE is its offset
    assert len(shown) == 3 * (3 + 4 + 4)
    for f, frame in enumerate(frames):
        panels = shown[11 * f:11 * (f + 1)]
        np.testing.assert_array_equal(panels[0], frame.rgb)
        for pred, panel in zip(frame.predictions.values(), panels[7:], strict=True):
            np.testing.assert_array_equal(panel, viz.error_map(pred, frame.gt_m, np.ones_like(frame.gt_m, bool), 0.5))
    assert [t for t in texts if t.startswith("RMSE")] == ["RMSE 0.000 m", "RMSE 0.100 m", "RMSE 0.200 m",
                                                          "RMSE 0.400 m"] * 3
    frames[1] = dataclasses.replace(frames[1], predictions={"A": frames[1].gt_m})
    with pytest.raises(ValueError, match="has methods \\['A'\\], not \\['A', 'B', 'C', 'linear'\\]"):
        viz.save_comparison_grid(tmp_path / "bad.png", frames, max_m=10, max_error_m=0.5)


def test_fitting_range_is_the_models_unless_the_data_do_not_fit():
    rng = np.random.default_rng(0)
    indoor = rng.uniform(1, 8, (20, 30))
    assert viz.fitting_range(indoor, 10.0) == (0.0, 10.0)                     # fits: the fixed range
    street = np.concatenate([rng.uniform(5, 60, 990), np.full(10, 500.0), [0.0, np.nan, np.inf]])
    assert viz.fitting_range(street, 10.0) == (0.0, pytest.approx(np.percentile(street[:1000], 99)))
    assert viz.fitting_range(street, 10.0)[1] < 500                         # the 1 % outliers do not set it
    assert viz.fitting_range(indoor, 85.0) == (0.0, pytest.approx(np.percentile(indoor, 99)))  # under 85 / 4
    assert viz.fitting_range(np.zeros((4, 4)), 10.0) == (0.0, 10.0)
