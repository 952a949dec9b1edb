"""lip-any, the default model for rooms and streets: one `dataclasses.replace` of the mixed scene base (base.py).
The per-scene fast-prox models (lip-fast-<scene>, lip-ad-fast-<scene>) are the equal-budget study's (paper.py).

The fast prox (lipjax.priors.fast "fast") has a third of the paper-style G's FLOPs per frame and trains ~2.7x faster
here, so it trains longer for the same CPU time. The runs (commands, overrides, curves): docs/training.md, "How the
shipped models were trained" (the run history: `git log -p -- docs/training.md`).
"""
from __future__ import annotations

import dataclasses

from experiments.configs.base import MIXED, Expected
from lipjax.train.config import TrainConfig

# lip-any: one model for rooms and streets, any sensor (issue 22), the default model; each run resumes from the
# shipped lip-any (its first run started from lip-fast-indoor: EXPECTED's note).
LIP_ANY = dataclasses.replace(
    MIXED, name="lip-any", init_from="lip-any", g_steps=4000, learning_rate=1e-4, warmup_steps=100,
    eval_every=500, checkpoint_every=250, keep_checkpoints=40,
    # the per-image log RMSE the suites score (docs/decisions/0009-log-rmse-loss.md); L1 until 676,000 images
    loss="log_rmse",
)

CONFIGS: dict[str, TrainConfig] = {
    "lip_any": LIP_ANY,
}

# What the shipped weights reached (lipjax/weights/<name>.json; the data each run read: its data_streams).
EXPECTED: dict[str, Expected] = {
    "lip_any": Expected(
        val_rmse_m=2.081812, images_seen=1_572_640, budget_from_config=False,
        note="its runs: 4,000 steps from the 100,000-image lip-fast-indoor at learning rate 2e-4 with z0 the "
             "linear fill, zoom 0.6-1.6 and texture probability 0.3 / strength 0.4, no camera noise (132,000 images; "
             "val 2.6348 m with z0 auto); then 4,000 steps of this config without relight, keypoints and holes from "
             "that model (164,000; val 2.5845 m); then 2,000 such steps (180,000; val 2.5571 m); then 4,000 such steps"
             " (212,000; val 2.5167 m, the mean of its last 4 checkpoints); then this config with --set g_steps=2000 "
             "from that one (228,000; val 2.4962 m, its last checkpoint), all five with texture on one rectangle, the "
             "reference camera and closed rooms; then eight cosine cycles of this config as it is now, each from the "
             "previous one's export (--set g_steps=7000, 4500, 4500, 3000, 3000, 3000, 3000, 3000 and --set "
             "init_from=<that export>: 284,000, 320,000, 356,000, 380,000, 404,000, 428,000, 452,000, 476,000 images),"
             " the last exported as the mean of its last 4 checkpoints (its runs 14-21), all eight on the data "
             "stream of seed 0; then this config with --set seed=25 from that one (500,000 images; val 2.3570 m, the "
             "mean of its last 4) and --set g_steps=2000 --set seed=26 from that (516,000; the mean of its last 4; "
             "shipped until 2026-12-03); then five runs of --set g_steps=3000 (--set g_steps=2000 for the first), "
             "each from the previous one's picked export with a seed of its own (27-31): 532,000, 556,000, 580,000, "
             "604,000, 628,000 images, the last three with --set data.clutter_prob=0.5 and the last also with --set "
             "data.foliage_prob=0.5; each picked by validation among its last checkpoint, the mean of its last 4 "
             "and their soup with the run before's pick (--soup); the last, the soup of the thirtieth's and the "
             "mean of the thirty-first's last 4 (628,000 images, shipped until 2026-12-04); then two more such "
             "runs with seeds 32 and 33 (652,000, 676,000), and the thirty-fourth with --set loss=log_rmse (this "
             "config's loss since; L1 before) from the thirty-third's soup (700,000 images, the soup of the two); "
             "then the thirty-fifth from that (seed 35): 724,000 images, the soup of its last checkpoint and the "
             "thirty-fourth's (shipped until 2026-12-04); then the thirty-sixth (seed 36, 748,000 images) and the "
             "thirty-seventh from its soup (seed 37): 772,000 images, the soup of the mean of its last 4 and the "
             "thirty-sixth's (shipped until 2026-12-04); then the thirty-eighth from that (seed 38): 796,000 images, "
             "the mean of its last 4 checkpoints (shipped until 2026-12-04); then the thirty-ninth (seed 39, "
             "820,000 images) and the fortieth (seed 40, 844,000), each the soup of its last checkpoint and the run "
             "before's pick, and the forty-first from the fortieth's (seed 41): 868,000 images, the soup of the mean "
             "of its last 4 and the fortieth's (shipped until 2026-12-04); then the forty-second (seed 42, 892,000 "
             "images) and the forty-third (seed 43, 916,000), and the forty-fifth from the forty-third's soup "
             "(seed 45, 4,080 steps on a GPU): 948,640 images, the soup of the mean of its last 4 and the "
             "forty-third's (shipped until 2026-12-04); then the forty-sixth from that (seed 46): 972,640 images, "
             "the mean of its last 4 checkpoints (shipped until 2026-12-04); then the forty-eighth (seed 48, "
             "996,640 images, the mean of its last 4), the forty-ninth (seed 49, 1,020,640, the soup of the mean of "
             "its last 4 and the forty-eighth's pick), the fiftieth (seed 50, 1,044,640, the mean of its last 4) and "
             "the fifty-first from that (seed 51): 1,068,640 images, the soup of its last checkpoint and the "
             "fiftieth's (shipped until 2026-12-04); then the fifty-second (seed 52, 1,092,640 images, the soup of "
             "its last checkpoint and the fifty-first's), the fifty-third (seed 53, 1,116,640, its last checkpoint) "
             "and the fifty-fourth from that (seed 54): 1,140,640 images, the soup of its last checkpoint and the "
             "fifty-third's (shipped until 2026-12-04); then the fifty-fifth (seed 55, 1,164,640 images, the soup "
             "of its last checkpoint and the fifty-fourth's), the fifty-sixth (seed 56, 1,188,640, the mean of its "
             "last 4), the fifty-seventh (seed 57, 1,212,640, the soup of its last checkpoint and the fifty-sixth's),"
             " the fifty-eighth (seed 58, 1,236,640, the mean of its last 4) and the fifty-ninth from that (seed 59):"
             " 1,260,640 images, the mean of its last 4 checkpoints (shipped until 2026-12-05); then the sixtieth "
             "(seed 60, 1,284,640 images, the soup of its last checkpoint and the fifty-ninth's), the sixty-first "
             "(seed 61, 1,308,640, the mean of its last 4), the sixty-second (seed 62, 1,332,640, the soup of its "
             "last checkpoint and the sixty-first's) and the sixty-third from that (seed 63): 1,356,640 images, its "
             "last checkpoint (shipped until 2026-12-05); then the sixty-fourth (seed 64, 1,380,640 images, its last "
             "checkpoint), the sixty-fifth (seed 65, 1,404,640, the soup of its last checkpoint and the "
             "sixty-fourth's), the sixty-sixth (seed 66, 1,428,640, the same soup), the sixty-seventh (seed 67, "
             "1,452,640, its last checkpoint) and the sixty-eighth from that (seed 68): 1,476,640 images, its last "
             "checkpoint (shipped until 2026-12-05); then the sixty-ninth (seed 69, 1,500,640 images, the soup of its "
             "last checkpoint and the sixty-eighth's), the seventieth (seed 70, 1,524,640, the same soup), the "
             "seventy-first (seed 71, 1,548,640, the mean of its last 4) and the seventy-second from that (seed 72): "
             "1,572,640 images, the soup of its last checkpoint and the seventy-first's, shipped by the rules of "
             "docs/decisions/0008-lip-any-ship-check.md (its runs 27-72: `git log -p -- docs/training.md`)"),
}
