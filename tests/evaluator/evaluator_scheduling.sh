#!/usr/bin/env bash
# The evaluator process runs at the CPU scheduling policy and nice value of its [evaluator] INI
# section: its main thread and every other thread (read from /proc/PID/task/*/stat: field 19 is
# the nice value, field 41 the policy, 5 for SCHED_IDLE, 3 for SCHED_BATCH), and it says so before
# its ready line; without the settings it keeps the ones it was started with.
# Usage: evaluator_scheduling.sh EVALUATOR_BINARY
set -euo pipefail
evaluator=$1
dir=$(mktemp -d)
pid=
cleanup() {
  [ -n "$pid" ] && kill "$pid" 2>/dev/null && wait "$pid" 2>/dev/null
  rm -rf "$dir"
}
trap cleanup EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }
# The expected values are from nice 0: started at another (a test run under `nice`), the
# evaluator could not reach them, as it only lowers its priority.
base=$(nice)
if [ "$base" -ne 0 ]; then
  echo "SKIP: started at nice $base; these checks start from nice 0"
  exit 77
fi

# check POLICY NICE POLICY_NUMBER SECTION [PREFIX...]: start the evaluator with that [evaluator]
# section (PREFIX before its command), check every thread for POLICY and NICE.
check() {
  printf '[evaluator]\n%b' "$4" > "$dir/run.ini"
  "${@:5}" "$evaluator" --config "$dir/run.ini" --out "$dir/run-$1" --run-id 7 --lcm-url memq:// \
    --lcm-bulk-url memq:// --lcm-samples-url memq:// > "$dir/log-$1" 2>&1 &
  pid=$!
  for _ in $(seq 300); do
    grep -q '^evaluator: ready' "$dir/log-$1" && break
    kill -0 "$pid" 2>/dev/null || { cat "$dir/log-$1"; fail "the evaluator exited"; }
    sleep 0.1
  done
  grep -q '^evaluator: ready' "$dir/log-$1" || fail "no ready line within 30 s"
  grep -qx "evaluator: scheduling $1, nice $2" "$dir/log-$1" || fail "no scheduling line: $(cat "$dir/log-$1")"
  local threads=0
  for stat in /proc/"$pid"/task/*/stat; do
    # The fields after the command name, which is in parentheses and may hold spaces.
    read -r -a f <<< "$(sed 's/^.*) //' "$stat")"
    # f[0] is field 3 (state): field N is f[N-3].
    [ "${f[16]}" = "$2" ] || fail "$stat: nice ${f[16]}, expected $2"
    [ "${f[38]}" = "$3" ] || fail "$stat: policy ${f[38]}, expected $3"
    threads=$((threads + 1))
  done
  kill "$pid"
  wait "$pid" || true
  pid=
  echo "ok: $1, nice $2 on all $threads threads"
}
check idle 0 5 'sched-policy = idle\n'
check batch 12 3 'sched-policy = batch\nnice = 12\n'
check normal 0 0 'sched-policy = normal\nnice = 0\n'
# Nothing set: the policy and nice value it was started with (here nice 7).
check normal 7 0 '' nice -n 7
# Only the nice value: the policy stays.
check normal 15 0 'nice = 15\n'
echo PASS
