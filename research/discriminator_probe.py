"""Can the LIP+AD discriminator tell real depth from a model's output at all? Held-out accuracy per D variant.

Run by hand (never a test):

    python -m research.discriminator_probe [--model lip-ad-indoor] [--steps 400] [--train 128] [--val 64]

G is frozen (the model given); its outputs on `--train` synthetic indoor train crops and `--val` val crops
(128x160, 200 uniform samples) are computed once. Each D variant then trains alone (Adam, batch 8, the
cross-entropy of lipjax.train.losses.discriminator_loss) on the train crops, and its accuracy on the held-out val
crops, 0.5 * (P(real logit > 0) + P(fake logit < 0)), is printed every 100 steps: 0.5 is chance. This isolates
D's ability from the adversarial game: a D that cannot beat chance here gives G no signal in LIP+AD.
"""
from __future__ import annotations

import argparse

import jax
import jax.numpy as jnp
import numpy as np
import optax

from lipjax.data.augment import Augment, augment_batch
from lipjax.data.pipeline import BatchIterator
from lipjax.data.sampling import sampler_from_spec
from lipjax.data.synthetic import SyntheticDataset
from lipjax.train.discriminator import Discriminator
from lipjax.inference import compiled_apply, load_model
from lipjax.train.losses import discriminator_loss

CROP = (128, 160)
BATCH = 8

VARIANTS = {
    "paper D (depth / max depth), lr 2e-4 (the shipped LIP+AD)": (Discriminator(), 2e-4),
    "paper D, lr 1e-3": (Discriminator(), 1e-3),
    "paper D, 4x wider, lr 1e-3": (Discriminator(widths=(32, 64, 128, 128)), 1e-3),
    "log-depth gradients, lr 2e-4": (Discriminator(inputs="log_gradients"), 2e-4),
    "log-depth gradients, lr 1e-3": (Discriminator(inputs="log_gradients"), 1e-3),
}


def crops(split: str, count: int, completer):
    """(rgb01, gt, valid, fake) arrays of `count` crops of the synthetic indoor `split`, fake = G's output."""
    dataset = SyntheticDataset("indoor", split, size=count, height=256, width=320)
    it = BatchIterator(dataset, BATCH, sampler_from_spec("uniform:200"), shuffle=False, drop_last=True, num_epochs=1)
    run = compiled_apply(completer.config, False)
    out = {"rgb": [], "gt": [], "valid": [], "fake": []}
    for step, batch in enumerate(it):
        batch = augment_batch(batch, Augment(), CROP, seed=0, step=step)
        host = completer.config.host_inputs(batch.sparse)
        fake = np.asarray(run(completer.params, batch.rgb, batch.sparse, host)[0])
        out["rgb"].append(batch.rgb.astype(np.float32) / 255.0)
        out["gt"].append(batch.gt)
        out["valid"].append(batch.gt_valid)
        out["fake"].append(fake)
    return {k: jnp.asarray(np.concatenate(v)) for k, v in out.items()}


def probe(d: Discriminator, lr: float, train, val, steps: int, seed: int = 0) -> list[float]:
    params = d.init(jax.random.key(seed), CROP)
    opt = optax.adam(lr)
    opt_state = opt.init(params)

    def loss_fn(p, rgb, gt, valid, fake):
        return discriminator_loss(d.apply(p, gt, rgb, valid), d.apply(p, fake, rgb, valid))

    @jax.jit
    def step(p, s, rgb, gt, valid, fake):
        grads = jax.grad(loss_fn)(p, rgb, gt, valid, fake)
        updates, s = opt.update(grads, s, p)
        return optax.apply_updates(p, updates), s

    @jax.jit
    def accuracy(p):
        real = d.apply(p, val["gt"], val["rgb"], val["valid"])
        fake = d.apply(p, val["fake"], val["rgb"], val["valid"])
        return 0.5 * (jnp.mean(real > 0) + jnp.mean(fake < 0))

    rng = np.random.default_rng(seed)
    n = train["gt"].shape[0]
    accs = []
    for i in range(1, steps + 1):
        idx = rng.choice(n, BATCH, replace=False)
        params, opt_state = step(params, opt_state, *(train[k][idx] for k in ("rgb", "gt", "valid", "fake")))
        if i % 100 == 0:
            accs.append(float(accuracy(params)))
    return accs


def main(argv=None) -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--model", default="lip-ad-indoor")
    p.add_argument("--steps", type=int, default=400)
    p.add_argument("--train", type=int, default=128)
    p.add_argument("--val", type=int, default=64)
    args = p.parse_args(argv)
    completer = load_model(args.model)
    train, val = crops("train", args.train, completer), crops("val", args.val, completer)
    print(f"G = {args.model}; {args.train} train / {args.val} held-out crops {CROP[0]}x{CROP[1]}; "
          f"held-out D accuracy (0.5 = chance) after each 100 steps of batch {BATCH}\n")
    marks = list(range(100, args.steps + 1, 100))
    print("| D variant | " + " | ".join(f"step {m}" for m in marks) + " |")
    print("|---|" + "---:|" * len(marks))
    for name, (d, lr) in VARIANTS.items():
        accs = probe(d, lr, train, val, args.steps)
        print(f"| {name} | " + " | ".join(f"{a:.3f}" for a in accs) + " |", flush=True)


if __name__ == "__main__":
    main()
