"""Clutter for rooms (lipjax.data.synthetic.clutter): the same room with things on its floor where the camera looks,
drawn from a stream of its own, off unless asked for, on training frames only."""
from __future__ import annotations

import math

import numpy as np
import pytest

from lipjax.data import synthetic as S
from lipjax.data.sources import open_source
from lipjax.data.synthetic.clutter import CLUTTER, add_clutter
from lipjax.data.synthetic.dataset import clutter_rng
from lipjax.data.synthetic.primitives import _Box
from lipjax.train.config import DataConfig

H, W = 48, 64
OBJECT = S.LABELS.index("object")


def _room(index: int):
    return S.build_scene("indoor", S.frame_rngs("indoor", "train", index)[0])


def test_clutter_adds_things_on_the_floor_inside_the_room_in_view_and_keeps_the_room():
    for index in range(6):
        room = _room(index)
        cluttered = add_clutter(room, np.random.default_rng(index))
        assert cluttered.prims[:len(room.prims)] == room.prims and len(cluttered.prims) > len(room.prims)
        shell = next(p for p in room.prims if isinstance(p, _Box) and p.inside)
        forward = room.cam_R[:, 2]
        bearing0 = math.atan2(forward[0], forward[2])
        for p in cluttered.prims[len(room.prims):]:
            lo, hi = p.hull().min(axis=0), p.hull().max(axis=0)
            assert lo[1] >= -1e-6  # on or above the floor
            centre = (lo + hi) / 2
            assert np.all(np.abs(centre[[0, 2]] - np.asarray(shell.c)[[0, 2]]) < np.asarray(shell.h)[[0, 2]])
            dx, dz = centre[0] - room.cam_pos[0], centre[2] - room.cam_pos[2]
            off = (math.atan2(dx, dz) - bearing0 + math.pi) % (2 * math.pi) - math.pi
            assert abs(off) < CLUTTER.half_view + 0.6  # in view (a wall clip or a tabletop thing's offset aside)
        # drawn from the stream alone: the same stream, the same things
        again = add_clutter(_room(index), np.random.default_rng(index))
        assert [p.c for p in again.prims] == [p.c for p in cluttered.prims]


def test_a_cluttered_room_shows_its_things_and_nothing_else_of_the_room_moves():
    frame, info = S.render_with_info("indoor", "train", 3, H, W)
    cluttered, cinfo = S.render_with_info("indoor", "train", 3, H, W, clutter=clutter_rng("train", 3))
    assert (cinfo.labels == OBJECT).mean() > (info.labels == OBJECT).mean() + 0.02
    changed = cluttered.depth != frame.depth
    assert changed.any() and np.all(cinfo.labels[changed] == OBJECT)  # only the things are new
    assert np.all(cluttered.depth[changed] < frame.depth[changed])  # in front of what they hide
    np.testing.assert_array_equal(cinfo.camera_to_world, info.camera_to_world)
    with pytest.raises(ValueError, match="clutter is for rooms"):
        S.render_with_info("outdoor", "train", 3, H, W, clutter=clutter_rng("train", 3))


def test_the_dataset_clutters_a_share_of_its_rooms_decided_per_frame_and_validation_never():
    plain = S.SyntheticDataset("indoor", "train", size=12, height=H, width=W)
    always = S.SyntheticDataset("indoor", "train", size=12, height=H, width=W, clutter_prob=1.0)
    half = S.SyntheticDataset("indoor", "train", size=12, height=H, width=W, clutter_prob=0.5)
    assert "clutter_prob=1.0" in repr(always) and "clutter" not in repr(plain)
    for i in range(12):
        np.testing.assert_array_equal(plain[i].depth, S.render("indoor", "train", i, H, W).depth)  # 0: as built
        assert not np.array_equal(always[i].depth, plain[i].depth)
        np.testing.assert_array_equal(always[i].depth, always[i].depth)  # the same frame every time
    drawn = [clutter_rng("train", i).random() < 0.5 for i in range(12)]
    assert [not np.array_equal(half[i].depth, plain[i].depth) for i in range(12)] == drawn and 0 < sum(drawn) < 12
    mixed = DataConfig(kind="mixed", height=H, width=W, clutter_prob=1.0, val_images=2)
    train, val = open_source(mixed, "train").dataset, open_source(mixed, "val").dataset
    assert train.parts[0].clutter_prob == 1.0 and train.parts[1].clutter_prob == 0.0  # rooms only
    assert val.parts[0].clutter_prob == 0.0  # validation: the rooms as built
    with pytest.raises(ValueError, match="data.clutter_prob needs rooms"):
        open_source(DataConfig(kind="outdoor", clutter_prob=0.5), "train")
    with pytest.raises(ValueError, match="clutter_prob is for rooms"):
        S.SyntheticDataset("outdoor", "train", size=2, height=H, width=W, clutter_prob=0.5)
    for bad in (-0.1, 1.5, "x"):
        with pytest.raises(ValueError, match="clutter_prob must be a probability"):
            S.SyntheticDataset("indoor", "train", size=2, height=H, width=W, clutter_prob=bad)
