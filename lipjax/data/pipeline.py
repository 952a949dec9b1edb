"""Batches for training and evaluation: deterministic, resumable, loaded in worker processes, placed on devices.

    dataset[i] -> protocol -> sampler (keyed by the example id) -> Batch -> augment + crop -> z0 -> shard_batch

Order. Step s of a run maps to (epoch, offset) = divmod(s, steps_per_epoch); epoch e visits the examples in
a permutation drawn from (seed, e) (or in order when shuffle=False). So batch s is a pure function of
(dataset, seed, s): a run resumed at step s yields exactly what the original run would have yielded from
step s on, and every epoch has a different order.

Self-supervision. A sampler that `withholds` its input (lipjax.data.hidden.HiddenInput) leaves each example's ground
truth only where its input has no sample, before and after the augmentation; training draws its input anew each
epoch (`redraw_each_epoch`: `redraw_seed`), still a pure function of (seed, s).

Workers. `TrainLoader` runs the whole per-step work (reading, sampling, augmentation and crop, the host z0
fill) in `num_workers` grain worker processes (grain.IterDataset.mp_prefetch): element s of its grain
MapDataset is this process's batch of step s, so the worker count changes the speed, never the batches, and a
resumed run's loader starts at its step.

Multi-host. Every process builds the same BatchIterator (same seed, same global batch_size) with its own
process_index / process_count = jax.process_index() / jax.process_count(); it loads only its contiguous
slice of each global batch, and shard_batch assembles the slices into global arrays sharded over the
1-D 'data' mesh axis (jax.make_array_from_process_local_data). One CPU, several GPUs and several hosts run
the same code.
"""
from __future__ import annotations

import dataclasses
import gc
import math
from typing import Any, Iterator, Sequence

import numpy as np

from lipjax.data.augment import Augment, augment_batch
from lipjax.data.frame import Batch, Frame
from lipjax.data.hidden import HiddenInput, without_input
from lipjax.data.sampling import SparseSampler
from lipjax.utils import exit_when_orphaned

DATA_AXIS = "data"
EVAL_BATCH_SIZE = 4
WORKER_BUFFER = 2  # batches each worker process prepares ahead


class BatchIterator:
    """Deterministic, resumable batches of (protocol-applied) Frames with their sparse inputs.

    Args:
      dataset: indexable: len(dataset) and dataset[i] -> Frame (raw frames).
      batch_size: GLOBAL batch size (over all processes).
      sampler: draws the sparse input, sampler(frame, sample_seed) -> (H, W) float32 metres.
      protocol: applied to each Frame before sampling (None: frames must already share one size).
      seed: seed of the per-epoch shuffles.
      shuffle: permute each epoch (training) or keep dataset order (evaluation).
      drop_last: drop the last incomplete batch of an epoch (required when process_count > 1).
      start_step: first global step to yield (resume point = batches already consumed).
      num_epochs: stop after this many epochs (counted from epoch 0); None = endless.
      process_index, process_count: this process's slice of each global batch.
      sample_seed: seed passed to the sampler; the sparse points of an example depend only on it and the id.
    """

    def __init__(self, dataset: Any, batch_size: int, sampler: SparseSampler, protocol: Any = None, *,
                 seed: int = 0, shuffle: bool = True, drop_last: bool = True, start_step: int = 0,
                 num_epochs: int | None = None, process_index: int = 0, process_count: int = 1,
                 sample_seed: int = 0):
        if batch_size < 1:
            raise ValueError(f"batch_size must be >= 1, got {batch_size}")
        if not 0 <= process_index < process_count:
            raise ValueError(f"process_index {process_index} not in [0, {process_count})")
        if batch_size % process_count:
            raise ValueError(f"global batch_size {batch_size} is not divisible by process_count {process_count}")
        if process_count > 1 and not drop_last:
            raise ValueError("drop_last=False is not supported with several processes (uneven last batch)")
        if start_step < 0:
            raise ValueError(f"start_step must be >= 0, got {start_step}")
        self.dataset, self.batch_size, self.sampler, self.protocol = dataset, batch_size, sampler, protocol
        self.seed, self.shuffle, self.drop_last = seed, shuffle, drop_last
        self.start_step, self.num_epochs = start_step, num_epochs
        self.process_index, self.process_count = process_index, process_count
        self.sample_seed = sample_seed
        self.num_examples = len(dataset)
        self.steps_per_epoch = (self.num_examples // batch_size if drop_last
                                else math.ceil(self.num_examples / batch_size))
        if self.steps_per_epoch == 0:
            raise ValueError(f"dataset of {self.num_examples} examples gives no batch of {batch_size} "
                             f"(drop_last={drop_last})")

    @property
    def local_batch_size(self) -> int:
        return self.batch_size // self.process_count

    def position(self, step: int) -> tuple[int, int]:
        """Global step -> (epoch, batch offset within the epoch)."""
        return divmod(step, self.steps_per_epoch)

    def epoch_order(self, epoch: int) -> np.ndarray:
        """(num_examples,) int64 dataset indices in the order epoch `epoch` visits them."""
        if not self.shuffle:
            return np.arange(self.num_examples)
        return np.random.default_rng([self.seed, epoch]).permutation(self.num_examples)

    def global_indices(self, step: int) -> np.ndarray:
        """Dataset indices of the whole global batch of `step`."""
        epoch, offset = self.position(step)
        return self.epoch_order(epoch)[offset * self.batch_size : (offset + 1) * self.batch_size]

    def local_indices(self, step: int) -> np.ndarray:
        """Dataset indices of this process's slice of the global batch of `step`."""
        indices = self.global_indices(step)
        per = len(indices) // self.process_count
        return indices[self.process_index * per : (self.process_index + 1) * per]

    def example(self, index: int, epoch: int | None = None) -> tuple[Frame, np.ndarray]:
        """(protocol-applied Frame, (H, W) float32 sparse depth in metres) of dataset[index]. A sampler that
        `withholds` its input from the ground truth (lipjax.data.hidden.HiddenInput) gives a Frame whose ground truth
        is where the input has no sample (lipjax.data.hidden.without_input); one that asks to `redraw_each_epoch`
        draws with `redraw_seed` of `epoch` (training; None: sample_seed, as validation draws)."""
        frame = self.dataset[int(index)]
        if self.protocol is not None:
            frame = self.protocol(frame)
        seed = self.sample_seed
        if epoch is not None and isinstance(self.sampler, HiddenInput) and self.sampler.redraw_each_epoch:
            seed = redraw_seed(self.sample_seed, self.seed, epoch)
        sparse = np.asarray(self.sampler(frame, seed), dtype=np.float32)
        if sparse.shape != frame.shape:
            raise ValueError(f"sampler returned {sparse.shape} for {frame.id!r} of shape {frame.shape}")
        if isinstance(self.sampler, HiddenInput) and self.sampler.withholds:
            frame = without_input(frame, sparse)
        return frame, sparse

    def examples(self, step: int) -> list[tuple[Frame, np.ndarray]]:
        """This process's examples of global step `step`, as `example` gives them (frames of any sizes)."""
        epoch = self.position(step)[0]
        return [self.example(i, epoch) for i in self.local_indices(step)]

    def batch(self, step: int) -> Batch:
        """This process's Batch of global step `step` (a pure function of the step); its frames must share one
        size (StepBatches crops frames of several sizes one by one)."""
        return stacked(self.examples(step), f"step {step}")

    @property
    def end_step(self) -> int | None:
        """First step not yielded (None when endless)."""
        return None if self.num_epochs is None else self.num_epochs * self.steps_per_epoch

    def __len__(self) -> int:
        if self.end_step is None:
            raise TypeError("an endless BatchIterator (num_epochs=None) has no length")
        return max(0, self.end_step - self.start_step)

    def __iter__(self) -> Iterator[Batch]:
        step = self.start_step
        while self.end_step is None or step < self.end_step:
            yield self.batch(step)
            step += 1


def redraw_seed(sample_seed: int, seed: int, epoch: int) -> int:
    """The sampler's seed in `epoch` of a run of shuffle seed `seed`, for samplers that draw new samples each epoch
    (`redraw_each_epoch`): a pure function of the three, so that batch s stays a pure function of (seed, s)."""
    return int(np.random.SeedSequence([sample_seed, seed, epoch]).generate_state(1)[0])


def stacked(examples: list[tuple[Frame, np.ndarray]], what: str = "a batch") -> Batch:
    """A Batch of (Frame, sparse) examples of one size; a one-line ValueError names the sizes otherwise."""
    shapes = {s.shape for s, _ in examples}
    if len(shapes) > 1:
        raise ValueError(f"the frames of {what} have different sizes {sorted(shapes)}; train with a crop "
                         "(data.crop, lipjax train --crop H W) or a protocol that brings them to one size")
    return Batch(
        rgb=np.stack([s.rgb for s, _ in examples]),
        sparse=np.stack([y for _, y in examples]),
        gt=np.stack([s.depth for s, _ in examples]),
        gt_valid=np.stack([s.valid for s, _ in examples]),
    )


def with_host_inputs(model_config: Any, batch: Batch) -> Batch:
    """Adds the host-computed initial estimate z0 (metres) to a (cropped) batch for models that need one: the
    model config's `host_inputs(sparse)`; None (no model) adds nothing."""
    extra = {} if model_config is None else model_config.host_inputs(batch.sparse)
    return dataclasses.replace(batch, **extra) if extra else batch


def validation_batches(source: Any, model_config: Any, batch_size: int = EVAL_BATCH_SIZE) -> list[Batch]:
    """Every frame of a Source (lipjax.data.sources) at full size, in order, with its z0: a fixed validation set.

    Consecutive frames of one size share a batch of up to `batch_size`; a frame of another size starts a new one,
    so frames of several sizes (a folder of KITTI drives: 370x1224, 375x1242, ...) are each validated whole, at
    their own size (the metrics are per image, then averaged: the batching does not change them)."""
    it = BatchIterator(source.dataset, min(batch_size, len(source.dataset)), source.sampler, shuffle=False,
                       drop_last=False, num_epochs=1)
    batches, run = [], []
    for index in range(len(source.dataset)):
        example = it.example(index)
        if run and (len(run) == batch_size or example[0].shape != run[0][0].shape):
            batches.append(stacked(run))
            run = []
        run.append(example)
    return [with_host_inputs(model_config, b) for b in batches + [stacked(run)]]


@dataclasses.dataclass(frozen=True)
class StepBatches:
    """A grain data source whose element s is this process's finished training batch of global step s.

    Element s = with_host_inputs(augment_batch(iterator.batch(s))), as a dict of arrays plus "step": the
    reading, sampling, augmentation, crop and z0 fill of a step all run wherever the element is made (a
    worker process). Picklable when the data set and sampler are.
    """

    iterator: BatchIterator
    num_steps: int
    augment: Augment
    crop: tuple[int, int] | None
    seed: int
    model_config: Any

    def __len__(self) -> int:
        return self.num_steps

    def __getitem__(self, step: int) -> dict[str, np.ndarray]:
        step = int(step)
        first = self.iterator.local_batch_size * self.iterator.process_index
        examples = self.iterator.examples(step)
        if self.crop is not None and len({s.shape for s, _ in examples}) > 1:
            # frames of several sizes: each is augmented and cropped on its own, with the draws it would have in
            # one batch (augment_batch keys them by the example's place in the global batch), then stacked
            parts = [augment_batch(stacked([e]), self.augment, self.crop, self.seed, step, first + i)
                     for i, e in enumerate(examples)]
            batch = Batch(*(np.concatenate(arrays) for arrays in zip(*((p.rgb, p.sparse, p.gt, p.gt_valid)
                                                                          for p in parts))))
        else:
            batch = augment_batch(stacked(examples, f"step {step}"), self.augment, self.crop, self.seed, step, first)
        sampler = self.iterator.sampler
        if isinstance(sampler, HiddenInput) and sampler.withholds:  # no ground truth where a zoom put an input sample
            keep = batch.gt_valid & (batch.sparse <= 0)
            batch = dataclasses.replace(batch, gt=np.where(keep, batch.gt, 0).astype(np.float32), gt_valid=keep)
        return {"step": np.int64(step), **with_host_inputs(self.model_config, batch).as_dict()}


def _grain():
    """grain, with absl flags marked parsed when the program has not parsed them (grain reads its flags)."""
    import grain
    from absl import flags

    if not flags.FLAGS.is_parsed():
        flags.FLAGS.mark_as_parsed()
    return grain


def _single_threaded_worker(worker_index: int, worker_count: int) -> None:
    """Each worker process uses one core: OpenCV's own thread pool would make the workers compete for cores.
    Workers ignore SIGINT and SIGTERM: a terminal's Ctrl-C, `timeout` and a batch scheduler's preemption signal the
    whole process group, and the training loop, not each worker, decides what the signal means (lipjax.train.loop:
    save the step in progress, then stop the workers); a worker that died of it first would take that step's batch
    with it. A worker ends with the run even when the run is killed (SIGKILL): `lipjax.utils.exit_when_orphaned`."""
    import signal

    import cv2

    cv2.setNumThreads(1)
    for signum in (signal.SIGINT, signal.SIGTERM):
        signal.signal(signum, signal.SIG_IGN)
    exit_when_orphaned()


class TrainLoader:
    """Training batches of steps [first_step, len(steps)) from `num_workers` grain worker processes, in order.

    Args:
      steps: a StepBatches.
      first_step: the first step it loads (a run's start, or the step a checkpoint resumes at).
      num_workers: worker processes (0: one background thread in this process).
    Batch s is a function of s alone (StepBatches), so a resumed run starts a new loader at its step: no grain
    iterator state is saved or restored (grain 0.2.18, given a state, waits forever for its worker's
    acknowledgement when that worker died starting). Iterating yields Batch; each element's step is checked against
    the expected one, so a loader that went wrong fails loudly instead of training on the wrong batches.
    """

    def __init__(self, steps: StepBatches, first_step: int = 0, num_workers: int = 0):
        grain = _grain()
        dataset = grain.MapDataset.source(steps)[first_step:].to_iter_dataset(
            grain.ReadOptions(num_threads=1, prefetch_buffer_size=WORKER_BUFFER))
        if num_workers > 0:
            dataset = dataset.mp_prefetch(grain.MultiprocessingOptions(num_workers=num_workers,
                                                                       per_worker_buffer_size=WORKER_BUFFER),
                                          worker_init_fn=_single_threaded_worker)
        self._iterator = iter(dataset)
        self.next_step = first_step

    def __iter__(self) -> "TrainLoader":
        return self

    def __next__(self) -> Batch:
        arrays = dict(next(self._iterator))
        step = int(arrays.pop("step"))
        if step != self.next_step:
            raise RuntimeError(f"the data loader yielded step {step}, expected {self.next_step}")
        self.next_step += 1
        # Copied out of the workers' shared memory at once, so that grain unlinks it now, while the loader runs:
        # a batch still in hand when a signal stops the run would leak its segments ("leaked shared_memory").
        return Batch(**{k: None if v is None else np.array(v) for k, v in arrays.items()})

    def close(self) -> None:
        """Stops the worker processes and frees grain's iterators now (not at interpreter exit, where their
        finalisers fail noisily)."""
        if self._iterator is not None:
            self._iterator.close()
            self._iterator = None
            gc.collect()

    def __enter__(self) -> "TrainLoader":
        return self

    def __exit__(self, *exc) -> None:
        self.close()


def make_data_mesh(devices: Sequence[Any] | None = None):
    """A 1-D jax.sharding.Mesh with axis 'data' over `devices` (default: all devices of all processes)."""
    import jax  # imported lazily so data-only users do not pay for it

    devices = jax.devices() if devices is None else list(devices)
    return jax.sharding.Mesh(np.asarray(devices), (DATA_AXIS,))


def shard_batch(batch: Batch, mesh=None) -> dict[str, Any]:
    """Places a process-local Batch as global jax.Arrays sharded along the batch dim over mesh axis 'data'.

    Args:
      batch: this process's slice of the global batch (BatchIterator with process_index / process_count).
      mesh: a 1-D mesh with axis 'data' (default make_data_mesh()).
    Returns:
      {"rgb", "sparse", "gt", "gt_valid"[, "z0"]} -> jax.Array with the GLOBAL batch dim (local batch x processes),
      sharded with NamedSharding(mesh, PartitionSpec('data')); dtypes as in Batch.
    Raises:
      ValueError if the local batch does not split evenly over this process's devices.
    """
    import jax
    from jax.sharding import NamedSharding, PartitionSpec

    mesh = make_data_mesh() if mesh is None else mesh
    if tuple(mesh.axis_names) != (DATA_AXIS,):
        raise ValueError(f"shard_batch needs a 1-D mesh with axis {DATA_AXIS!r}, got axes {mesh.axis_names}")
    sharding = NamedSharding(mesh, PartitionSpec(DATA_AXIS))
    local_devices = [d for d in mesh.devices.flat if d.process_index == jax.process_index()]
    arrays = {k: np.asarray(v) for k, v in batch.as_dict().items()}
    local_batch = arrays["rgb"].shape[0]
    if local_batch % len(local_devices):
        raise ValueError(
            f"local batch size {local_batch} is not divisible by the {len(local_devices)} local devices of the "
            f"'data' mesh axis ({mesh.devices.size} devices in all); choose a batch size that is a multiple of it"
        )
    return {name: jax.make_array_from_process_local_data(sharding, array) for name, array in arrays.items()}
