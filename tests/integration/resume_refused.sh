#!/usr/bin/env bash
# `launch.sh --resume` of a run whose replay snapshot, then whose learner state, has been
# corrupted: the process refuses the file at its start, and the launcher stops at once (within
# seconds, not at the end of the time budget) with a non-zero status and the process's own error
# on its output. (An earlier launch's "ready" line in the same log must not count.)
source "$(dirname "$0")/lib.sh"
isolate "$@"
scratch
launch cartpole --out "$dir/run" --actors 2 --seed 6 --goal 100000 --time-budget 240 \
  > "$dir/first.log" 2>&1 &
wait_line "$dir/first.log" "running; logs in" 60
wait_learner_state "$dir/run"
"$root/scripts/launch.sh" --stop "$dir/run" > "$dir/stop.log" 2>&1 || fail "--stop: $(cat "$dir/stop.log")"
wait
[ -s "$dir/run/replay-snapshot.bin" ] || fail "no replay snapshot after the stop"

# Overwrites 64 bytes in the middle of FILE (keeping a copy in FILE.good).
corrupt() {
  local size
  cp "$1" "$1.good"
  size=$(stat -c %s "$1")
  head -c 64 /dev/urandom | dd of="$1" bs=1 seek=$((size / 2)) conv=notrunc status=none
}
# Resumes the run with a time budget of 120 s and expects it to stop within 30 s with ROLE's
# error on the launcher's output.
expect_refused() {  # expect_refused ROLE LOG
  local role=$1 log=$2 start status elapsed
  start=$(date +%s)
  set +e
  timeout 200 "$root/scripts/launch.sh" --resume "$dir/run" --no-setup --build-dir "$build_dir" \
    --time-budget 120 > "$log" 2>&1
  status=$?
  set -e
  elapsed=$(( $(date +%s) - start ))
  cat "$log"
  [ "$status" -ne 0 ] || fail "the resume with a corrupted $role file exited with 0"
  [ "$elapsed" -lt 30 ] || fail "the resume with a corrupted $role file took $elapsed s to stop"
  grep -q "^launch: $role failed at its start" "$log" || fail "the launcher did not say $role failed"
  grep -q "^$role: error: " "$log" || fail "the $role's own error is not on the launcher's output"
  echo "$role refused its file: stopped after $elapsed s with status $status"
}

corrupt "$dir/run/replay-snapshot.bin"
expect_refused replay "$dir/resume-replay.log"
mv "$dir/run/replay-snapshot.bin.good" "$dir/run/replay-snapshot.bin"

corrupt "$dir/run/checkpoints/learner-state.bin"
expect_refused learner "$dir/resume-learner.log"
echo "PASS: a refused snapshot or learner state stops a resumed run at once, with its error"
