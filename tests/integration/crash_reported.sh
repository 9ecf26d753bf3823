#!/usr/bin/env bash
# A process that crashes is restarted, and the restart says how it died: the launcher's line
# names the signal ("signal 11 (SIGSEGV)"), and lib.sh's expect_no_restarts, which every test
# that kills nothing calls at its end, fails on it, naming the process, the signal and its last
# log lines.
source "$(dirname "$0")/lib.sh"
isolate "$@"
scratch
ulimit -c 0
launch cartpole --out "$dir/run" --actors 1 --seed 7 --goal 1000000 --time-budget 120 \
  > "$dir/launch.log" 2>&1 &
wait_line "$dir/launch.log" "running; logs in" 60
learner=$(awk '$1 == "learner" {p = $2} END {print p}' "$dir/run/pids")
kill -SEGV "$learner"
wait_line "$dir/run/restarts" " learner status 139 restart 1$" 30
wait_line "$dir/launch.log" "^launch: learner was killed by signal 11 (SIGSEGV) after .*; restarting it in 1 s (restart 1 of 5)" 10
wait_line "$dir/run/logs/learner.log" "^learner: ready .*resumed at update\|^learner: ready .*nothing to resume" 30
"$root/scripts/launch.sh" --stop "$dir/run" > "$dir/stop.log" 2>&1 || fail "--stop: $(cat "$dir/stop.log")"
wait || true
set +e
(expect_no_restarts "$dir/run") > "$dir/check.log" 2>&1
status=$?
set -e
cat "$dir/check.log"
[ "$status" -ne 0 ] || fail "expect_no_restarts passed a run whose learner crashed"
grep -q "^learner was killed by signal 11 (SIGSEGV) at " "$dir/check.log" || fail "the check did not say how"
grep -q "^FAIL: .*learner (was killed by signal 11 (SIGSEGV))" "$dir/check.log" || fail "no summary"
grep -q "^  learner: ready" "$dir/check.log" || fail "the check did not show the learner's log"
echo "PASS: the crash was restarted, and reported as signal 11 (SIGSEGV)"
