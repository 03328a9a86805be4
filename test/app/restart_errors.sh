#!/usr/bin/env bash
# `cfdmpm --restart` refuses what it cannot continue from, with exit code 2 and a message that names
# the file or the directory and what is wrong, and leaves the output directory as it was.
set -u
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
failures=0
# expect <name> <substring of the message> -- <cfdmpm arguments...>
expect() {
  local name=$1 needle=$2
  shift 3
  (cd "$work" && "$CFDMPM" "$@") > "$work/$name.out" 2> "$work/$name.err"
  local code=$?
  if [ "$code" != 2 ]; then
    echo "FAIL $name: exit code $code, expected 2"; cat "$work/$name.err"; failures=$((failures + 1)); return
  fi
  if ! grep -qF -- "$needle" "$work/$name.err"; then
    echo "FAIL $name: message lacks '$needle':"; cat "$work/$name.err"; failures=$((failures + 1)); return
  fi
  echo "ok   $name: $(head -c 300 "$work/$name.err")"
}

# A good run with checkpoints to spoil: the dam break of the restart tests for 0.02 s.
sed -e "s|OUTPUT|out|" -e "s|END|0.02|" "$SOURCE_DIR/test/app/restart/dam-break.yaml" > "$work/scene.yaml"
(cd "$work" && "$CFDMPM" scene.yaml > run.log 2>&1) || { echo "FAIL the run to restart from"; cat "$work/run.log"; exit 1; }
checkpoint=$(ls "$work/out/checkpoints/" | tail -n 1)
[ -n "$checkpoint" ] || { echo "FAIL the run wrote no checkpoint"; exit 1; }
(cd "$work/out" && find . -type f -exec md5sum {} + | sort) > "$work/before"

expect missing_path "'no-such-run' is neither a checkpoint file nor an output directory" -- --restart no-such-run
expect no_option_value "--restart needs a checkpoint file or an output directory" -- --restart
mkdir -p "$work/empty"
expect no_checkpoint "no checkpoint in 'empty/checkpoints'" -- --restart empty
head -c 2000 "$work/out/checkpoints/$checkpoint" > "$work/truncated.h5"
expect truncated "checkpoint 'truncated.h5': not a readable HDF5 file" -- --restart truncated.h5
printf 'not HDF5\n' > "$work/text.h5"
expect not_hdf5 "checkpoint 'text.h5': not a readable HDF5 file" -- --restart text.h5
expect step_file "checkpoint 'out/scene_000000.h5': not a cfdmpm checkpoint" -- --restart out/scene_000000.h5
cp "$work/out/checkpoints/$checkpoint" "$work/moved.h5"
expect moved "checkpoint 'moved.h5': not in the checkpoints/ folder of an output directory" -- --restart moved.h5
mkdir -p "$work/copy/checkpoints"
cp "$work/out/checkpoints/$checkpoint" "$work/no-density.h5"
"$PYTHON" -c "import h5py, sys; del h5py.File(sys.argv[1], 'r+')['cells/state/density']" "$work/no-density.h5"
mv "$work/no-density.h5" "$work/copy/checkpoints/"
expect missing_field "checkpoint 'copy/checkpoints/no-density.h5': no dataset /cells/state/density" -- --restart copy/checkpoints/no-density.h5
sed -e "s|cells: \[50, 20\]|cells: [40, 20]|" "$work/scene.yaml" > "$work/other-grid.yaml"
expect other_grid "does not fit the checkpoint" -- --restart out other-grid.yaml
expect with_check "--check and --restart do not go together" -- --check --restart out

(cd "$work/out" && find . -type f -exec md5sum {} + | sort) > "$work/after"
cmp -s "$work/before" "$work/after" || { echo "FAIL a refused restart changed the output directory"; failures=$((failures + 1)); }
[ "$failures" = 0 ] && echo "PASS" || exit 1
