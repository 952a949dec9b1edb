"""Batch pipeline: determinism, per-epoch reshuffle, exact resume, worker processes, process slices, sharding."""
from __future__ import annotations

import itertools
import os
import subprocess
import sys

import numpy as np
import pytest

from lipjax.data.augment import Augment
from lipjax.data.frame import Batch, Frame, Intrinsics
from lipjax.data.pipeline import BatchIterator, StepBatches, TrainLoader
from lipjax.data.protocols import EvalProtocol, Resize
from lipjax.data.sampling import UniformSampler

H, W = 6, 8


def fake_dataset(n: int = 10) -> list[Frame]:
    """Frame i has depth i + 1 everywhere (minus a few holes), so batches reveal which examples they hold."""
    out = []
    for i in range(n):
        rng = np.random.default_rng(i)
        depth = np.full((H, W), i + 1.0, np.float32)
        depth[rng.random((H, W)) < 0.2] = 0
        rgb = rng.integers(0, 256, (H, W, 3), dtype=np.uint8)
        out.append(Frame.from_depth(rgb, depth, Intrinsics(10, 10, W / 2, H / 2), f"fake/{i:03d}"))
    return out


def example_ids(batch: Batch) -> list[int]:
    return [int(gt.max()) - 1 for gt in batch.gt]


def batches_equal(a: Batch, b: Batch) -> bool:
    a, b = a.as_dict(), b.as_dict()
    return a.keys() == b.keys() and all(np.array_equal(a[k], b[k]) for k in a)


def make(dataset=None, **kwargs) -> BatchIterator:
    return BatchIterator(dataset if dataset is not None else fake_dataset(), kwargs.pop("batch_size", 3),
                         UniformSampler(5), **kwargs)


def test_batch_contents():
    batch = make(shuffle=False).batch(0)
    assert batch.rgb.shape == (3, H, W, 3) and batch.rgb.dtype == np.uint8
    assert batch.sparse.shape == batch.gt.shape == batch.gt_valid.shape == (3, H, W)
    assert batch.sparse.dtype == batch.gt.dtype == np.float32 and batch.gt_valid.dtype == np.bool_
    assert example_ids(batch) == [0, 1, 2]
    assert all(np.count_nonzero(y) == 5 for y in batch.sparse) and np.all(batch.gt_valid[batch.sparse > 0])


def test_deterministic_and_seeded():
    a = list(itertools.islice(make(seed=1), 6))
    b = list(itertools.islice(make(seed=1), 6))
    c = list(itertools.islice(make(seed=2), 6))
    assert all(batches_equal(x, y) for x, y in zip(a, b))
    assert [example_ids(x) for x in a] != [example_ids(x) for x in c]


def test_each_epoch_is_a_new_permutation():
    it = make(seed=0, batch_size=3)  # 10 examples -> 3 steps per epoch, 1 dropped
    assert it.steps_per_epoch == 3 and it.position(7) == (2, 1)
    epochs = [sum((example_ids(it.batch(e * 3 + k)) for k in range(3)), []) for e in range(3)]
    for order in epochs:
        assert len(set(order)) == 9  # no repeats within an epoch
    assert len({tuple(order) for order in epochs}) == 3  # three different orders
    assert example_ids(make(shuffle=False).batch(3)) == [0, 1, 2]  # no shuffle: dataset order every epoch


def test_resume_from_start_step_equals_continuing():
    full = list(itertools.islice(make(seed=5), 8))
    resumed = list(itertools.islice(make(seed=5, start_step=4), 4))
    assert len(resumed) == 4 and all(batches_equal(x, y) for x, y in zip(full[4:], resumed, strict=True))


def test_finite_epochs_and_drop_last():
    it = make(num_epochs=2, shuffle=False, drop_last=False)
    batches = list(it)
    assert len(batches) == len(it) == 8 and [len(b.gt) for b in batches[:4]] == [3, 3, 3, 1]
    assert len(make(num_epochs=2, start_step=5)) == 1


def test_protocol_and_sparse_seed():
    tiny = EvalProtocol("tiny", (Resize(3, 4),), (3, 4), 0.0, 10.0)
    batch = make(protocol=tiny).batch(0)
    assert batch.gt.shape == (3, 3, 4)
    a, b = make(sample_seed=0).batch(0), make(sample_seed=1).batch(0)
    assert np.array_equal(a.gt, b.gt) and not np.array_equal(a.sparse, b.sparse)
    with pytest.raises(ValueError, match="different sizes"):
        make(fake_dataset(2) + [Frame.from_depth(np.zeros((2, 2, 3), np.uint8), np.ones((2, 2), np.float32),
                                                     Intrinsics(1, 1, 1, 1), "odd")], shuffle=False).batch(0)


def test_process_slices_are_disjoint_and_cover_the_global_batch():
    parts = [make(batch_size=4, seed=3, process_index=p, process_count=2) for p in range(2)]
    for step in range(5):
        local = [p.local_indices(step) for p in parts]
        assert np.array_equal(np.concatenate(local), parts[0].global_indices(step))
        assert example_ids(parts[1].batch(step)) == local[1].tolist()
    with pytest.raises(ValueError, match="divisible"):
        make(batch_size=3, process_count=2)


def step_batches(process_index=0, process_count=1, dataset=None) -> StepBatches:
    it = make(dataset, batch_size=4, seed=9, process_index=process_index, process_count=process_count)
    return StepBatches(it, 12, Augment(), (4, 6), 9, None)


def test_step_batches_crop_and_slice_like_the_global_batch():
    whole = step_batches()[5]
    halves = [step_batches(p, 2)[5] for p in range(2)]
    assert whole["gt"].shape == (4, 4, 6) and int(whole["step"]) == 5
    for key in ("rgb", "sparse", "gt", "gt_valid"):  # each process crops its examples as one process would
        assert np.array_equal(np.concatenate([h[key] for h in halves]), whole[key])


def test_worker_processes_equal_in_process_loading_and_resume_at_a_step():
    with TrainLoader(step_batches(), 0, num_workers=0) as loader:
        serial = [next(loader) for _ in range(8)]
    with TrainLoader(step_batches(), 0, num_workers=2) as loader:
        parallel = [next(loader) for _ in range(5)]
    assert all(batches_equal(x, y) for x, y in zip(serial, parallel))
    for workers in (2, 0):  # a resumed run's loader starts at its step, with any worker count
        with TrainLoader(step_batches(), 5, num_workers=workers) as resumed:
            assert resumed.next_step == 5 and all(batches_equal(x, next(resumed)) for x in serial[5:])


class Exploding:
    """A dataset whose example 4 is corrupt."""

    def __init__(self):
        self.items = fake_dataset()

    def __len__(self):
        return len(self.items)

    def __getitem__(self, i):
        if i == 4:
            raise RuntimeError("corrupt example 4")
        return self.items[i]


def test_loader_reraises_a_data_error_in_order():
    it = make(Exploding(), shuffle=False, batch_size=2)
    consumed = []
    with pytest.raises(RuntimeError, match="corrupt example 4"):
        with TrainLoader(StepBatches(it, 5, Augment(), None, 0, None), 0, num_workers=0) as loader:
            for _ in range(5):
                consumed.append(example_ids(next(loader)))
    assert consumed == [[0, 1], [2, 3]]


def test_shard_batch_single_device():
    import jax

    from lipjax.data.pipeline import make_data_mesh, shard_batch

    batch = make(shuffle=False, batch_size=2).batch(0)
    mesh = make_data_mesh(jax.devices()[:1])
    arrays = shard_batch(batch, mesh)
    assert set(arrays) == {"rgb", "sparse", "gt", "gt_valid"}
    assert arrays["gt"].shape == (2, H, W) and np.array_equal(np.asarray(arrays["gt"]), batch.gt)
    assert arrays["rgb"].dtype == np.uint8 and arrays["gt_valid"].dtype == np.bool_


MULTI_DEVICE_SCRIPT = r"""
import numpy as np, jax
from lipjax.data.frame import Frame, Intrinsics
from lipjax.data.pipeline import BatchIterator, make_data_mesh, shard_batch
from lipjax.data.sampling import UniformSampler
assert jax.device_count() == 4, jax.devices()
data = [Frame.from_depth(np.full((4, 5, 3), i, np.uint8), np.full((4, 5), i + 1.0, np.float32),
                          Intrinsics(5, 5, 2, 2), f"d/{i}") for i in range(16)]
it = BatchIterator(data, 8, UniformSampler(3), seed=0)
batch = it.batch(1)
arrays = shard_batch(batch, make_data_mesh())
gt = arrays["gt"]
assert gt.shape == (8, 4, 5) and len(gt.addressable_shards) == 4, gt.addressable_shards
assert sorted(s.device.id for s in gt.addressable_shards) == [0, 1, 2, 3]
for shard in gt.addressable_shards:
    assert shard.data.shape == (2, 4, 5)
    rows = shard.index[0]
    assert np.array_equal(np.asarray(shard.data), batch.gt[rows])
assert np.array_equal(np.asarray(arrays["sparse"]), batch.sparse)
assert gt.sharding.spec == jax.sharding.PartitionSpec("data")
try:
    shard_batch(BatchIterator(data, 6, UniformSampler(3)).batch(0), make_data_mesh())
except ValueError as e:
    assert "not divisible" in str(e), e
else:
    raise AssertionError("expected a divisibility error")
print("SHARDED_OK")
"""


def test_shard_batch_over_four_forced_host_devices():
    env = {**os.environ, "XLA_FLAGS": "--xla_force_host_platform_device_count=4", "JAX_PLATFORMS": "cpu"}
    result = subprocess.run([sys.executable, "-c", MULTI_DEVICE_SCRIPT], env=env, capture_output=True, text=True,
                            timeout=120)
    assert result.returncode == 0 and "SHARDED_OK" in result.stdout, result.stderr[-3000:]
