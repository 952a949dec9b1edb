"""Batches for training and evaluation: deterministic, resumable, prefetched, and placed across devices.

    dataset[i] -> protocol -> sampler (keyed by the example id) -> Batch -> shard_batch -> jax.Arrays

Order. Step s of a run maps to (epoch, offset) = divmod(s, steps_per_epoch); epoch e visits the examples in
a permutation drawn from (seed, e) (or in order when shuffle=False). So batch s is a pure function of
(dataset, seed, s): a run resumed with start_step=s yields exactly what the original run would have yielded
from step s on, and every epoch has a different order.

Multi-host. Every process builds the same BatchIterator (same seed, same global batch_size) with its own
process_index / process_count = jax.process_index() / jax.process_count(); it loads only its contiguous
slice of each global batch, and shard_batch assembles the slices into global arrays sharded over the
1-D 'data' mesh axis (jax.make_array_from_process_local_data). One CPU, several GPUs and several hosts run
the same code.
"""
from __future__ import annotations

import concurrent.futures
import dataclasses
import math
import queue
import threading
from typing import Any, Iterable, Iterator, Sequence

import numpy as np

from lipjax.data.sample import Batch, Sample
from lipjax.data.sampling import SparseSampler

DATA_AXIS = "data"


class BatchIterator:
    """Deterministic, resumable batches of (protocol-applied) Samples with their sparse inputs.

    Args:
      dataset: indexable: len(dataset) and dataset[i] -> Sample (raw frames).
      batch_size: GLOBAL batch size (over all processes).
      sampler: draws the sparse input, sampler(sample, sample_seed) -> (H, W) float32 metres.
      protocol: applied to each Sample before sampling (None: samples must already share one size).
      seed: seed of the per-epoch shuffles.
      shuffle: permute each epoch (training) or keep dataset order (evaluation).
      drop_last: drop the last incomplete batch of an epoch (required when process_count > 1).
      start_step: first global step to yield (resume point = batches already consumed).
      num_epochs: stop after this many epochs (counted from epoch 0); None = endless.
      process_index, process_count: this process's slice of each global batch.
      sample_seed: seed passed to the sampler; the sparse points of an example depend only on it and the id.
      num_workers: threads loading the examples of a batch in parallel (0: load in the calling thread).
    """

    def __init__(self, dataset: Any, batch_size: int, sampler: SparseSampler, protocol: Any = None, *,
                 seed: int = 0, shuffle: bool = True, drop_last: bool = True, start_step: int = 0,
                 num_epochs: int | None = None, process_index: int = 0, process_count: int = 1,
                 sample_seed: int = 0, num_workers: int = 0):
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
        self.sample_seed, self.num_workers = sample_seed, num_workers
        self.num_examples = len(dataset)
        self.steps_per_epoch = self.num_examples // batch_size if drop_last else math.ceil(self.num_examples / batch_size)
        if self.steps_per_epoch == 0:
            raise ValueError(f"dataset of {self.num_examples} examples gives no batch of {batch_size} (drop_last={drop_last})")
        self._pool: concurrent.futures.ThreadPoolExecutor | None = None

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

    def example(self, index: int) -> tuple[Sample, np.ndarray]:
        """(protocol-applied Sample, (H, W) float32 sparse depth in metres) of dataset[index]."""
        sample = self.dataset[int(index)]
        if self.protocol is not None:
            sample = self.protocol(sample)
        sparse = np.asarray(self.sampler(sample, self.sample_seed), dtype=np.float32)
        if sparse.shape != sample.shape:
            raise ValueError(f"sampler returned {sparse.shape} for {sample.id!r} of shape {sample.shape}")
        return sample, sparse

    def batch(self, step: int) -> Batch:
        """This process's Batch of global step `step` (a pure function of the step)."""
        indices = self.local_indices(step)
        if self.num_workers > 0:
            if self._pool is None:
                self._pool = concurrent.futures.ThreadPoolExecutor(self.num_workers, thread_name_prefix="lipjax-data")
            examples = list(self._pool.map(self.example, indices))  # map keeps the order
        else:
            examples = [self.example(i) for i in indices]
        shapes = {s.shape for s, _ in examples}
        if len(shapes) > 1:
            raise ValueError(f"examples of step {step} have different sizes {sorted(shapes)}; use a protocol")
        return Batch(
            rgb=np.stack([s.rgb for s, _ in examples]),
            sparse=np.stack([y for _, y in examples]),
            gt=np.stack([s.depth for s, _ in examples]),
            gt_valid=np.stack([s.valid for s, _ in examples]),
        )

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

    def close(self) -> None:
        """Stops the loading threads (if any)."""
        if self._pool is not None:
            self._pool.shutdown(wait=True, cancel_futures=True)
            self._pool = None

    def __enter__(self) -> "BatchIterator":
        return self

    def __exit__(self, *exc) -> None:
        self.close()


@dataclasses.dataclass
class _Raised:
    error: BaseException


_DONE = object()


def _put(q: queue.Queue, stop: threading.Event, item: Any) -> bool:
    """Puts unless stopped; polls so that a stop request is noticed while the queue is full."""
    while not stop.is_set():
        try:
            q.put(item, timeout=0.1)
            return True
        except queue.Full:
            continue
    return False


def _produce(iterator: Iterator[Any], q: queue.Queue, stop: threading.Event) -> None:
    try:
        for item in iterator:
            if not _put(q, stop, item):
                return
    except BaseException as error:  # noqa: BLE001 - handed to the consumer, which re-raises it
        _put(q, stop, _Raised(error))
        return
    _put(q, stop, _DONE)


class Prefetch:
    """Iterates `iterable` in a background thread, up to `buffer_size` items ahead.

    Items come out in the same order as from the iterable; an exception raised by the iterable is re-raised
    in the consumer (at the point where the failing item would have arrived). close() (or leaving a `with`
    block, or exhausting the iterator) stops the thread; a producer blocked on a full queue notices within
    0.1 s.
    """

    def __init__(self, iterable: Iterable[Any], buffer_size: int = 2):
        if buffer_size < 1:
            raise ValueError(f"buffer_size must be >= 1, got {buffer_size}")
        self._queue: queue.Queue = queue.Queue(maxsize=buffer_size)
        self._stop = threading.Event()
        self._finished = False
        # The thread must not reference self, so an abandoned Prefetch is collected and __del__ stops it.
        self._thread = threading.Thread(target=_produce, args=(iter(iterable), self._queue, self._stop),
                                        name="lipjax-prefetch", daemon=True)
        self._thread.start()

    def __iter__(self) -> "Prefetch":
        return self

    def __next__(self) -> Any:
        if self._finished:
            raise StopIteration
        item = self._queue.get()
        if item is _DONE:
            self.close()
            raise StopIteration
        if isinstance(item, _Raised):
            self.close()
            raise item.error
        return item

    def close(self) -> None:
        """Stops the producer and waits for it."""
        self._finished = True
        self._stop.set()
        while True:  # unblock a producer waiting on a full queue
            try:
                self._queue.get_nowait()
            except queue.Empty:
                break
        if self._thread is not threading.current_thread():
            self._thread.join(timeout=10.0)

    def __enter__(self) -> "Prefetch":
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def __del__(self) -> None:
        if not getattr(self, "_finished", True):
            self._finished = True
            self._stop.set()


def prefetch(iterable: Iterable[Any], buffer_size: int = 2) -> Prefetch:
    """Background-thread prefetch of `buffer_size` items (see Prefetch)."""
    return Prefetch(iterable, buffer_size)


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
