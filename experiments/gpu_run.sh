#!/bin/bash
# The equal-budget study (python -m experiments.equal_budget) on a GPU host with many cores, in one call of a fixed
# time, from the repository root:
#
#   OUT=/tmp/out [BUDGET_S=560] [WORKERS=14] [IMAGES=30000] [STUDY_ARGS="--scene indoor --seeds 1,2"] [WHEELS=DIR] \
#       bash experiments/gpu_run.sh
#
# Runs the study under `timeout` (SIGTERM: the run in progress saves a checkpoint of its step and stops; SIGKILL 30 s
# later if anything still runs) in runs/study, going on from the committed tuning, scores and runs in progress
# (experiments/study_scores, experiments/warm_starts/study: in the working tree that travels), then packs into OUT:
# log.txt, scores.tgz (the tuning and scores, and the report) and models.tgz.* (15 MB parts; the device tool brings
# back 8 files and 64 MB at most, so give a call no more work than 4 parts hold: a trunk's checkpoint is ~17 MB):
# every method's model at the budget IMAGES, and what this call wrote of the runs it left unfinished
# (--save-in-progress: each trunk's and cool-down's newest checkpoint and the exports the cool-downs still need).
# Back on the CPU machine, in the repository root:
#
#   tar xzf scores.tgz && cat models.tgz.* | tar xzf -     # then commit experiments/study_scores
#
# and the CPU study (python -m experiments.equal_budget) skips what the GPU finished and goes on from its unfinished
# runs where runs/study has no workdir of that run (remove the CPU's own, the study stopped, where the GPU's
# checkpoint is further). TINY=1: the tiny check (tiny networks, 48x64 frames, a few images) in its own root,
# scores and warm starts, runs/study-tiny, to test it on a CPU.
set -u
T0=$(date +%s)
STAMP=$(mktemp)  # what the call writes is newer
: "${OUT:?OUT=output folder}"
BUDGET_S=${BUDGET_S:-560}
RESERVE_S=${RESERVE_S:-60}
WORKERS=${WORKERS:-14}
IMAGES=${IMAGES:-30000}
ROOT=runs/study
SCORES=experiments/study_scores
WARM=experiments/warm_starts/study
ARGS="${STUDY_ARGS:-}"
if [ -n "${TINY:-}" ]; then
  ROOT=runs/study-tiny
  SCORES=$ROOT/scores
  WARM=$ROOT/warm-starts
  IMAGES=96
  ARGS="--tiny --curve 48,96 --tune-images 32 --cooldown 0.5 --limit 2 --methods ma2018,lip-cnn,lip-ad $ARGS"
fi
LOG=$OUT/log.txt
mkdir -p "$OUT" "$ROOT"
. "$(dirname "$0")/gpu_env.sh"
LEFT=$(( BUDGET_S - ($(date +%s) - T0) - RESERVE_S ))
echo "== the study for $LEFT s: $ARGS" >> "$LOG"
STUDY="python3 -m experiments.equal_budget --root $ROOT --scores $SCORES --warm-starts $WARM --images $IMAGES"
timeout -s TERM -k 30 "$LEFT" $STUDY --results "$ROOT/report" --workers "$WORKERS" --no-progress $ARGS >> "$LOG" 2>&1
echo "== the study ended ($?) at $(( $(date +%s) - T0 )) s" >> "$LOG"
$STUDY --results "$ROOT/report" --report $ARGS >> "$LOG" 2>&1
$STUDY --save-in-progress $ARGS >> "$LOG" 2>&1
tar czf "$OUT/scores.tgz" "$SCORES" "$ROOT/report"
{ ls -d "$ROOT"/*/*/lr*/seed*/"$IMAGES"/model.* 2>/dev/null; find "$WARM" -type f -newer "$STAMP" 2>/dev/null; } \
  | tar czf - -T - | split -b 15M - "$OUT/models.tgz."
rm -f "$STAMP"
echo "== done at $(( $(date +%s) - T0 )) s" >> "$LOG"
