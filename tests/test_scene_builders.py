"""The synthetic scenes as element builders: the public build_scene path renders the same frames as `render`, and
each builder keeps to the ranges its dataclass states."""
from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from lipjax.data import synthetic as S
from lipjax.data.synthetic.furniture import FREE_FURNITURE, WALL_FURNITURE, furniture
from lipjax.data.synthetic.indoor import INDOOR_CAMERA, ROOM, Room, indoor_camera
from lipjax.data.synthetic.outdoor import OUTDOOR_CAMERA, outdoor_camera
from lipjax.data.synthetic.scene import _Builder
from lipjax.data.synthetic.street import STREET, STYLES, street_layout


@pytest.mark.parametrize("kind", S.SYNTHETIC_KINDS)
def test_build_scene_and_render_scene_give_the_rendered_frame(kind):
    frame, info = S.render_with_info(kind, "val", 4, 40, 56)
    scene_rng, noise_rng = S.frame_rngs(kind, "val", 4)
    scene = S.build_scene(kind, scene_rng)
    rgb, depth, labels = S.render_scene(scene, 40, 56, S.intrinsics_for(kind, 40, 56), noise_rng)
    np.testing.assert_array_equal(rgb, frame.rgb)
    np.testing.assert_array_equal(depth, frame.depth)
    np.testing.assert_array_equal(labels, info.labels)
    np.testing.assert_array_equal(scene.cam_pos, info.camera_to_world[:3, 3])


def test_build_scene_names_the_kinds():
    with pytest.raises(ValueError, match="unknown synthetic kind 'forest'"):
        S.build_scene("forest", np.random.default_rng(0))


def test_range_tables_are_frozen():
    with pytest.raises(dataclasses.FrozenInstanceError):
        ROOM.width_m = (1.0, 2.0)
    with pytest.raises(dataclasses.FrozenInstanceError):
        STREET.lanes = (1, 9)


def test_streets_keep_to_their_ranges():
    streets = [street_layout(np.random.default_rng(seed)) for seed in range(300)]
    assert {s.style for s in streets} == set(STYLES)
    for s in streets:
        assert STREET.lane_width_m[0] <= s.lane_width <= STREET.lane_width_m[1]
        assert STREET.length_m[0] <= s.length <= STREET.length_m[1]
        assert s.lanes == 1 if s.style == "residential" else s.lanes in (1, 2)
        if s.style == "open":
            assert s.parking == 0.0 and s.sidewalk == 0.0
        assert s.half_width == s.lanes * s.lane_width + s.parking and s.edge == s.half_width + s.sidewalk


def test_cameras_keep_to_their_ranges():
    rng = np.random.default_rng(1)
    for _ in range(200):
        room = Room(rng.uniform(*ROOM.width_m), rng.uniform(*ROOM.length_m), rng.uniform(*ROOM.height_m))
        cam, R = indoor_camera(rng, room)
        assert INDOOR_CAMERA.height_m[0] <= cam[1] <= min(INDOOR_CAMERA.height_m[1], room.height - 0.45)
        assert 0.3 * room.width <= cam[0] <= 0.7 * room.width and 0.35 <= cam[2] <= 1.6
        np.testing.assert_allclose(R.T @ R, np.eye(3), atol=1e-12)
    for seed in range(200):
        street = street_layout(np.random.default_rng(seed))
        cam, _ = outdoor_camera(np.random.default_rng(seed + 1000), street)
        assert OUTDOOR_CAMERA.height_m[0] <= cam[1] <= OUTDOOR_CAMERA.height_m[1] and cam[2] == 0.0
        assert 0.0 < cam[0] < street.lanes * street.lane_width + 1.5  # in one of the right-hand lanes


@pytest.mark.parametrize("item", sorted({*WALL_FURNITURE, *FREE_FURNITURE}, key=lambda t: (t.kind, t.weight)),
                         ids=lambda t: t.kind)
def test_every_furniture_kind_is_one_shadow_caster_near_its_footprint(item):
    b = _Builder(np.random.default_rng(3))
    w, d, h = item.width_m[1], item.depth_m[1], item.height_m[1]
    furniture(b, b.rng, item.kind, (10.0, 20.0, 0.3), w, d, h)
    assert len(b.prims) >= 1 and len({p.asm for p in b.prims}) == 1
    corners = np.concatenate([p.hull() for p in b.prims])
    reach = np.hypot(w, d) / 2 + 1.0  # a chair in front of a desk or around a table reaches past the footprint
    assert np.all(np.hypot(corners[:, 0] - 10.0, corners[:, 2] - 20.0) <= reach)
    assert corners[:, 1].min() >= -1e-9 and corners[:, 1].max() <= max(h, 1.45 + 0.9) + 0.75
