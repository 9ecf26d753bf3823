#!/usr/bin/env bash
# The run's metrics time series (metrics.jsonl): rows for every role while the run goes, env steps
# that never go back, and only whole lines after a SIGKILL of the monitor that writes it.
source "$(dirname "$0")/lib.sh"
isolate "$@"
scratch
launch cartpole --out "$dir/run" --actors 2 --seed 2 --goal 1000000 --time-budget 120 \
  > "$dir/launch.log" 2>&1 &
launch_pid=$!
metrics="$dir/run/metrics.jsonl"
# Wait (polling the file, bounded) until the learner and the evaluator have a few rows each.
for _ in $(seq 600); do
  if [ -f "$metrics" ] && [ "$(grep -c '"role": "learner"' "$metrics")" -ge 4 ] &&
     grep -q '"role": "evaluator"' "$metrics"; then
    break
  fi
  kill -0 "$launch_pid" 2>/dev/null || { cat "$dir/launch.log"; fail "the run ended early"; }
  sleep 0.1
done
monitor=$(awk '$1 == "monitor" {print $2}' "$dir/run/pids")
[ -n "$monitor" ] || fail "no monitor in the pids file"
kill -KILL "$monitor"
wait "$launch_pid" || true  # the launch script stops the run when its monitor is gone
rows_before=$(wc -l < "$metrics")
for role in actor-0 actor-1 replay learner evaluator; do
  grep -q "\"role\": \"$role\"" "$metrics" || fail "no metrics rows of $role"
done
# Every line whole: an object from its first byte to its newline.
bad=$(grep -vc '^{"t": [0-9.e+-]*, "role": "[a-z0-9-]*".*}$' "$metrics" || true)
[ "$bad" -eq 0 ] || fail "$bad torn or malformed lines in metrics.jsonl"
[ "$(tail -c 1 "$metrics" | od -An -c | tr -d ' ')" = '\n' ] || fail "the last line is torn"
# Time and the learner's env steps never go back.
awk -F'"t": |, "role": "learner", ' '/"role": "learner"/ {
    split($0, a, "\"env_steps\": "); split(a[2], b, ","); steps = b[1] + 0
    split($2, c, ","); t = c[1] + 0
    if (t < last_t || steps < last_steps) { print "back at t=" t; exit 1 }
    last_t = t; last_steps = steps; n++ }
  END { if (n < 4) { print "only " n " learner rows"; exit 1 } }' "$metrics" ||
  fail "time or env steps went back"
expect_no_restarts "$dir/run"
echo "PASS: $rows_before metrics lines, every role, whole lines after SIGKILL of the monitor"
