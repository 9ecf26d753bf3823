#!/usr/bin/env bash
# The monitor's --history: a resumed run's progress line starts from the evaluations of its earlier
# parts (the last one scored and the best), before anything new is heard; a torn line of the file
# is skipped and counted. And with --metrics, its episodes count on from the metrics file's rows.
# Usage: monitor_history.sh MONITOR_BINARY
set -euo pipefail
monitor=$1
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
fail() { echo "FAIL: $*"; exit 1; }
cat > "$dir/eval.jsonl" <<'LINES'
{"checkpoint": "ckpt-000005000.bin", "update": 5000, "env_steps": 10000, "wall_seconds": 100, "mean": 500.5, "std": 10, "min": 480, "max": 520, "episodes": 100, "eval_seconds": 9}
{"checkpoint": "ckpt-000010000.bin", "update": 10000, "env_steps": 20000, "wall_seconds": 200, "mean": 742.65, "std": 10, "min": 700, "max": 760, "episodes": 100, "eval_seconds": 9}
{"checkpoint": "ckpt-000015000.bin", "update": 15000, "env_steps": 30000, "wall_seconds": 300, "mean": 659.75, "std": 10, "min": 600, "max": 700, "episodes": 100, "eval_seconds": 9}
{"checkpoint": "ckpt-0000200
LINES
# memq://: nothing reaches the monitor but the file; it prints lines until its budget is spent.
run_monitor() {  # run_monitor OUT [ARGS...]
  local out=$1 status=0
  shift
  "$monitor" --lcm-url memq:// --lcm-bulk-url memq:// --lcm-samples-url memq:// --goal 900 \
    --time-budget 1 --print-seconds 0.2 "$@" > "$out" 2> "$out.err" || status=$?
  [ "$status" -eq 1 ] || fail "the monitor exited with $status, not 1 (budget spent): $(cat "$out.err")"
}
run_monitor "$dir/with" --history "$dir/eval.jsonl"
lines=$(grep -c '^\[ *[0-9.]*s\] steps ' "$dir/with" || true)
[ "$lines" -ge 3 ] || fail "only $lines progress lines: $(cat "$dir/with")"
shown=$(grep '^\[ *[0-9.]*s\] steps ' "$dir/with" | grep -c 'eval 659.7 (best 742.6)' || true)
[ "$shown" -eq "$lines" ] || fail "not every progress line shows the history's last and best: $(cat "$dir/with")"
grep -q "monitor: 1 unreadable lines in $dir/eval.jsonl" "$dir/with.err" ||
  fail "the torn line was not counted: $(cat "$dir/with.err")"
# Without the file (a new run) there is no evaluation to show yet.
run_monitor "$dir/without"
grep -q 'eval -  learner' "$dir/without" || fail "a monitor without history showed an evaluation"
# A missing file is a new run's: no evaluation, no complaint.
run_monitor "$dir/missing" --history "$dir/none.jsonl"
grep -q 'eval -  learner' "$dir/missing" || fail "a missing history showed an evaluation"
[ ! -s "$dir/missing.err" ] || fail "a missing history was complained about: $(cat "$dir/missing.err")"
# The metrics of earlier parts: actor-0 ran 40 episodes, was restarted and ran 12; actor-1 ran 30.
cat > "$dir/metrics.jsonl" <<'LINES'
{"t": 10, "role": "actor-0", "env_steps": 9000, "episodes": 40}
{"t": 10, "role": "actor-1", "env_steps": 8000, "episodes": 30}
{"t": 20, "role": "actor-0", "env_steps": 9500, "episodes": 12}
LINES
run_monitor "$dir/metrics" --metrics "$dir/metrics.jsonl"
grep -q '\] steps 0  episodes 82  return' "$dir/metrics" ||
  fail "the episodes of the earlier parts were not counted: $(cat "$dir/metrics")"
echo "PASS: $lines progress lines from the history (last 659.7, best 742.6), the torn line" \
  "counted; 82 episodes from the metrics file"
