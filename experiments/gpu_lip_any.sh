#!/bin/bash
# One run of lip-any's chain in a fixed time on a GPU host with many cores (a lent 16-core H200), from the repository
# root (docs/training.md, "How the shipped models were trained"):
#
#   INIT=experiments/warm_starts/lip-any-next SEED=45 OUT=/tmp/out [WHEELS=DIR] [BUDGET_S=585] [STEPS=N] \
#       bash experiments/gpu_lip_any.sh
#
# The lip_any recipe of the CPU runs (clutter, porous trees, log RMSE) from INIT with its own SEED, 14 loader
# workers. Without STEPS a PROBE_S-second probe of the same command measures images/s and g_steps is set to what
# fills BUDGET_S (a multiple of 120); validation and checkpoints come every g_steps / 12, so that the mean of the last
# 4 spans the run's last third, as in the 3,000-step runs. Writes OUT/log.txt, OUT/metrics.jsonl and the exports
# OUT/lip-any<SEED>-last and -avg4 (or, if exporting fails, the workdir as OUT/ckpt.tgz.* in 15 MB parts).
# WHEELS: a folder of wheels installed first (no index, no dependencies), for a host without grain and the like.
set -u
T0=$(date +%s)
: "${INIT:?INIT=model to start from}" "${SEED:?SEED=a seed no run of the chain has had}" "${OUT:?OUT=output folder}"
BUDGET_S=${BUDGET_S:-585}
PROBE_S=${PROBE_S:-100}
RESERVE_S=${RESERVE_S:-60}
LOG=$OUT/log.txt
mkdir -p "$OUT"
elapsed() { echo $(( $(date +%s) - T0 )); }
. "$(dirname "$0")/gpu_env.sh"
TRAIN="python3 -m experiments.train --config lip_any --no-progress --set init_from=$INIT --set seed=$SEED
  --set data.clutter_prob=0.5 --set data.foliage_prob=0.5 --set loss=log_rmse --set data.num_workers=14"
if [ -z "${STEPS:-}" ]; then
  timeout -s TERM "$PROBE_S" $TRAIN --workdir /tmp/probe --set g_steps=100000 --set eval_every=100000 \
    --set checkpoint_every=100000 >> "$LOG" 2>&1
  RATE=$(python3 -c "import json, statistics; rows = open('/tmp/probe/metrics.jsonl').read().splitlines()
r = [json.loads(l)['images_per_s'] for l in rows if 'images_per_s' in l][-6:]; print(statistics.median(r or [0]))")
  LEFT=$(( BUDGET_S - $(elapsed) - RESERVE_S ))
  STEPS=$(python3 -c "print(max(120, int($RATE * max($LEFT - 60, 0) / 8 / 120) * 120))")
  echo "== probe: $RATE images/s" >> "$LOG"
fi
EVERY=$(( STEPS / 12 ))
LEFT=$(( BUDGET_S - $(elapsed) - RESERVE_S ))
echo "== g_steps $STEPS, validation and checkpoints every $EVERY, $LEFT s left at $(elapsed) s" >> "$LOG"
W=/tmp/run$SEED
RUN="--workdir $W --set g_steps=$STEPS --set eval_every=$EVERY --set checkpoint_every=$EVERY --set keep_checkpoints=6"
timeout -s TERM "$LEFT" $TRAIN $RUN >> "$LOG" 2>&1
echo "== training ended ($?) at $(elapsed) s" >> "$LOG"
cp $W/metrics.jsonl "$OUT"/ 2>/dev/null
$TRAIN $RUN --export-only --export "$OUT/lip-any$SEED-last" >> "$LOG" 2>&1 &
$TRAIN $RUN --export-only --average 4 --export "$OUT/lip-any$SEED-avg4" >> "$LOG" 2>&1
wait
if [ ! -f "$OUT/lip-any$SEED-avg4.msgpack" ]; then
  echo "== exporting failed: the workdir is in ckpt.tgz.*" >> "$LOG"
  tar cf - -C $W . | gzip -1 | split -b 15M - "$OUT/ckpt.tgz."
fi
echo "== done at $(elapsed) s" >> "$LOG"
