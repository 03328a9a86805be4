#!/usr/bin/env bash
# The checkpoint keys of the scene: output.checkpoint_wall_interval (here 1 ns: a checkpoint after
# every step) and output.checkpoints_kept (3: only the newest three stay), and a restart with a
# scene given on the command line that lets the run go further (time.max_steps 10, then 20).
set -u
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
failures=0
fail() { echo "FAIL $*"; failures=$((failures + 1)); }
sed -e "s|OUTPUT|out|" -e "s|END|0.2|" -e "s|    checkpoint_interval: 0.02|    checkpoint_wall_interval: 1.0e-9\n    checkpoints_kept: 3|" \
    -e "s|    dt_max: 1.0e-3|    dt_max: 1.0e-3\n    max_steps: 10|" "$SOURCE_DIR/test/app/restart/dam-break.yaml" > "$work/scene.yaml"
sed -e "s|max_steps: 10|max_steps: 20|" "$work/scene.yaml" > "$work/longer.yaml"
grep -q "checkpoints_kept: 3" "$work/scene.yaml" && grep -q "max_steps: 10" "$work/scene.yaml" || { echo "FAIL the scene was not edited"; exit 1; }
cd "$work"
"$CFDMPM" scene.yaml > run.log 2>&1 || { echo "FAIL the first run"; cat run.log; exit 1; }
kept=$(ls out/checkpoints | tr '\n' ' ')
echo "after 10 steps: $kept"
[ "$kept" = "scene_000008.h5 scene_000009.h5 scene_000010.h5 " ] || fail "expected the checkpoints of steps 8, 9 and 10"
"$CFDMPM" --restart out longer.yaml > restart.log 2>&1 || { echo "FAIL the restart"; cat restart.log; exit 1; }
grep -q "restarted from out/checkpoints/scene_000010.h5: step 10" restart.log || fail "not restarted from the newest checkpoint"
kept=$(ls out/checkpoints | tr '\n' ' ')
echo "after 20 steps: $kept"
[ "$kept" = "scene_000018.h5 scene_000019.h5 scene_000020.h5 " ] || fail "expected the checkpoints of steps 18, 19 and 20"
steps=$(tail -n +2 out/scene.csv | cut -d, -f1 | tr '\n' ' ')
[ "$steps" = "$(seq 0 20 | tr '\n' ' ')" ] || fail "the CSV's steps are $steps, expected 0 to 20 once each"
[ "$failures" = 0 ] && echo "PASS" || exit 1
