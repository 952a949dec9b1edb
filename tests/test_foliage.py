"""Porous foliage for streets (lipjax.data.synthetic.foliage): the same street with its trees and bushes as clumps of
leaves inside the solid crowns, drawn from a stream of its own, off unless asked for, on training frames only."""
from __future__ import annotations

import numpy as np
import pytest

from lipjax.data import synthetic as S
from lipjax.data.sources import open_source
from lipjax.data.synthetic.dataset import foliage_rng
from lipjax.data.synthetic.foliage import FOLIAGE, porous_foliage
from lipjax.data.synthetic.primitives import _Spheres
from lipjax.train.config import DataConfig

H, W = 64, 96
VEGETATION = S.LABELS.index("vegetation")


def _street(index: int):
    return S.build_scene("outdoor", S.frame_rngs("outdoor", "train", index)[0])


def _leafy(n: int) -> list[int]:
    """The first n training streets whose solid foliage covers at least 3 % of a H x W frame."""
    out = []
    for i in range(100):
        _, info = S.render_with_info("outdoor", "train", i, H, W)
        if np.mean(info.labels == VEGETATION) >= 0.03:
            out.append(i)
        if len(out) == n:
            return out
    raise AssertionError("too few leafy streets")


def test_every_large_foliage_sphere_becomes_clumps_inside_it_and_nothing_else_changes():
    replaced = 0
    for index in range(4):
        street = _street(index)
        porous = porous_foliage(street, np.random.default_rng(index))
        assert len(porous.prims) == len(street.prims)
        for p, q in zip(street.prims, porous.prims):
            foliage = isinstance(p, _Spheres) and np.all(p.label == VEGETATION)
            if not foliage or not (p.rs >= FOLIAGE.min_radius_m).any():
                assert q is p  # the same primitive object: untouched
                continue
            assert q.mat is p.mat and q.asm == p.asm and q.cast == p.cast and len(q.rs) > len(p.rs)
            replaced += 1
            # each clump lies inside the sphere it replaces: |c' - c| + r' <= R for some big sphere (c, R)
            inside = (np.linalg.norm(q.cs[:, None, :].astype(np.float64) - p.cs[None].astype(np.float64), axis=2)
                      + q.rs[:, None] <= p.rs[None] * (1 + 1e-5) + 1e-6)
            assert inside.any(axis=1).all()
            small = p.rs < FOLIAGE.min_radius_m  # small spheres are kept as they are
            for c, r in zip(p.cs[small], p.rs[small]):
                assert np.any(np.all(q.cs == c, axis=1) & (q.rs == r))
        again = porous_foliage(_street(index), np.random.default_rng(index))
        assert all(np.array_equal(a.cs, b.cs) for a, b in zip(porous.prims, again.prims) if isinstance(a, _Spheres))
    assert replaced > 0  # the streets hold large foliage spheres: the checks above ran


def test_a_porous_street_is_seen_through_its_foliage_and_nowhere_else_moves():
    for index in _leafy(2):
        solid, info = S.render_with_info("outdoor", "train", index, H, W)
        porous, pinfo = S.render_with_info("outdoor", "train", index, H, W, foliage=foliage_rng("train", index))
        changed = porous.depth != solid.depth
        assert changed.any()
        assert np.all(info.labels[changed] == VEGETATION)  # only where the solid foliage was
        far = np.where(porous.valid, porous.depth, np.inf)[changed]
        assert np.all(far > solid.depth[changed])  # through the gaps: farther, or sky (no depth)
        assert np.any(pinfo.labels[info.labels == VEGETATION] != VEGETATION)  # something seen through the crowns
    with pytest.raises(ValueError, match="porous foliage is for streets"):
        S.render_with_info("indoor", "train", 0, H, W, foliage=foliage_rng("train", 0))


def test_the_dataset_makes_a_share_of_its_streets_porous_decided_per_frame_and_validation_never():
    leafy = _leafy(6)
    n = leafy[-1] + 1
    plain = S.SyntheticDataset("outdoor", "train", size=n, height=H, width=W)
    always = S.SyntheticDataset("outdoor", "train", size=n, height=H, width=W, foliage_prob=1.0)
    half = S.SyntheticDataset("outdoor", "train", size=n, height=H, width=W, foliage_prob=0.5)
    assert "foliage_prob=1.0" in repr(always) and "foliage" not in repr(plain)
    for i in leafy:
        np.testing.assert_array_equal(plain[i].depth, S.render("outdoor", "train", i, H, W).depth)  # 0: as built
        assert not np.array_equal(always[i].depth, plain[i].depth)
    drawn = [foliage_rng("train", i).random() < 0.5 for i in leafy]
    assert [not np.array_equal(half[i].depth, plain[i].depth) for i in leafy] == drawn and 0 < sum(drawn) < len(drawn)
    mixed = DataConfig(kind="mixed", height=H, width=W, foliage_prob=1.0, val_images=2)
    train, val = open_source(mixed, "train").dataset, open_source(mixed, "val").dataset
    assert train.parts[1].foliage_prob == 1.0 and train.parts[0].foliage_prob == 0.0  # streets only
    assert val.parts[1].foliage_prob == 0.0 and "foliage_prob=1.0" in repr(train)  # validation: solid trees
    with pytest.raises(ValueError, match="data.foliage_prob needs streets"):
        open_source(DataConfig(kind="indoor", foliage_prob=0.5), "train")
    with pytest.raises(ValueError, match="foliage_prob is for streets"):
        S.SyntheticDataset("indoor", "train", size=2, height=H, width=W, foliage_prob=0.5)
    for bad in (-0.1, 1.5, "x"):
        with pytest.raises(ValueError, match="foliage_prob must be a probability"):
            S.SyntheticDataset("outdoor", "train", size=2, height=H, width=W, foliage_prob=bad)


def test_a_porous_crown_casts_the_same_shadow_one_clump_at_a_time(monkeypatch):
    """shadows._split: a large sphere cluster casts as one caster per sphere (for speed); every pixel as when the
    whole crown is one caster."""
    from lipjax.data.synthetic import shadows

    index = _leafy(1)[0]
    split = S.render_with_info("outdoor", "train", index, H, W, foliage=foliage_rng("train", index))[0]
    assert shadows.SPLIT_SPHERES < FOLIAGE.clumps[0]  # a porous crown's blob is split
    monkeypatch.setattr(shadows, "SPLIT_SPHERES", 10**9)
    whole = S.render_with_info("outdoor", "train", index, H, W, foliage=foliage_rng("train", index))[0]
    np.testing.assert_array_equal(split.rgb, whole.rgb)
    np.testing.assert_array_equal(split.depth, whole.depth)
