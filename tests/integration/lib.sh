# Helpers of the multi-process integration tests (sourced by each test).
# Each test runs in its own network namespace when it can (root and unshare): `lo` up and a
# multicast route on it, so no LCM packet of a test reaches another test or the host.
set -euo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
build_dir=${RL_BUILD_DIR:?set RL_BUILD_DIR to the build directory}
bin="$build_dir/bin"

fail() { echo "FAIL: $*" >&2; exit 1; }

# Re-runs the calling test inside a fresh network namespace (once).
isolate() {
  if [ -z "${RL_IN_NETNS:-}" ] && [ "$(id -u)" -eq 0 ] && command -v unshare >/dev/null; then
    export RL_IN_NETNS=1
    exec unshare -n bash -c 'ip link set lo up && ip route add 224.0.0.0/4 dev lo && exec bash "$0" "$@"' "$0" "$@"
  fi
  if [ -z "${RL_IN_NETNS:-}" ]; then
    echo "note: not root; running on the host network with a random port" >&2
  fi
}

# Makes a fresh scratch folder $dir, removed on exit (after stopping any process of the test
# still running) unless RL_KEEP is set.
scratch() {
  dir=$(mktemp -d "${TMPDIR:-/tmp}/rl-it-XXXXXX")
  trap 'cleanup' EXIT
}
cleanup() {
  local pids
  # Processes a test froze (hold_learner_and_evaluator) go on, so that they can stop.
  # shellcheck disable=SC2086
  [ -z "${held:-}" ] || kill -CONT $held 2>/dev/null || true
  pids=$(jobs -p)
  [ -z "$pids" ] || kill $pids 2>/dev/null || true
  wait 2>/dev/null || true
  # Whatever a launch left behind (it stops its processes itself; this is the safety net).
  cat "$dir"/*/pids "$dir"/*/runs/*/pids 2>/dev/null | awk '{print $2}' | xargs -r kill -KILL 2>/dev/null || true
  [ -n "${RL_KEEP:-}" ] || rm -rf "$dir" 2>/dev/null || true
}

# Freezes the learner and the evaluator of the run in $run (SIGSTOP; their pids in $held), so
# that the run cannot reach its goal before what the test waits for (CartPole may learn faster
# than a process restarts). The test sends SIGCONT itself when it is time; cleanup does on exit.
hold_learner_and_evaluator() {
  local kind pid
  held=""
  for kind in learner evaluator; do
    pid=$(pgrep -f "^$bin/$kind --config $run/config.ini " | head -1)
    [ -n "$pid" ] || fail "no $kind process"
    held+=" $pid"
  done
  # shellcheck disable=SC2086
  kill -STOP $held
}

# The best evaluation mean in an eval.jsonl.
best_mean() { grep -Eo '"mean": *[-0-9.e+]+' "$1" | grep -Eo '[-0-9.e+]+$' | sort -g | tail -1; }

# Checks a finished run folder: its best evaluation mean is above MIN (at least MIN with
# "--at-least"), over 100 episodes; prints the best mean.
expect_best_mean() {  # expect_best_mean RUN_DIR MIN [--at-least]
  local jsonl="$1/eval.jsonl" min=$2 best
  [ -s "$jsonl" ] || fail "no eval.jsonl"
  best=$(best_mean "$jsonl")
  [ -n "$best" ] || fail "no evaluation in $jsonl"
  if [ "${3:-}" = "--at-least" ]; then
    awk -v b="$best" -v m="$min" 'BEGIN{exit !(b >= m)}' || fail "best evaluation mean $best < $min"
  else
    awk -v b="$best" -v m="$min" 'BEGIN{exit !(b > m)}' || fail "best evaluation mean $best <= $min"
  fi
  grep -E '"mean": *'"$best"'[,}]' "$jsonl" | grep -Eq '"episodes": *100[,}]' ||
    fail "the best evaluation did not use 100 episodes"
  echo "$best"
}

# Checks the replay's last progress line of a pixel run (kept in $replay_last and printed): it
# stored frames, and lost, dropped and missed nothing. replay_field NAME reads a number of it.
replay_field() { echo "$replay_last" | sed -n "s/.* $1 \([0-9]*\).*/\1/p"; }
expect_clean_pixel_replay() {  # expect_clean_pixel_replay RUN_DIR
  replay_last=$(grep '^replay: size' "$1/logs/replay.log" | tail -1)
  echo "$replay_last"
  [ -n "$replay_last" ] || fail "no progress line from the replay"
  [ "$(replay_field frames)" -gt 0 ] || fail "the replay stored no frames"
  [ "$(replay_field lost)" -eq 0 ] || fail "the replay lost messages"
  if [ "$(replay_field dropped)" -ne 0 ]; then
    grep -v '^replay: size' "$1/logs/replay.log" | tail -5 >&2
    fail "the replay dropped messages"
  fi
  [ "$(replay_field missing_frames)" -eq 0 ] || fail "transitions named frames that never arrived"
}

# Waits (bounded) until FILE has a line matching PATTERN.
wait_line() {  # wait_line FILE PATTERN TIMEOUT_SECONDS
  local file=$1 pattern=$2 limit=$3
  timeout "$limit" bash -c 'until grep -q -- "$1" "$0" 2>/dev/null; do sleep 0.05; done' "$file" "$pattern" ||
    fail "no line matching '$pattern' in $file within $limit s"
}

# Prints how many lines of FILE match PATTERN (0 for none, or while FILE does not exist yet).
lines() {  # lines FILE PATTERN
  local n
  n=$(grep -c -- "$2" "$1" 2>/dev/null)
  echo "${n:-0}"
}

# Waits (bounded) until FILE has at least COUNT lines matching PATTERN.
wait_lines() {  # wait_lines FILE PATTERN COUNT TIMEOUT_SECONDS
  local file=$1 pattern=$2 count=$3 limit=$4
  timeout "$limit" bash -c 'until n=$(grep -c -- "$1" "$0" 2>/dev/null); [ "${n:-0}" -ge "$2" ]; do
      sleep 0.05
    done' "$file" "$pattern" "$count" ||
    fail "fewer than $count lines matching '$pattern' in $file within $limit s"
}

# Waits (bounded) until the learner of the run in RUN_DIR has saved its state (it does with its
# first checkpoint).
wait_learner_state() {  # wait_learner_state RUN_DIR
  timeout 60 bash -c 'until [ -s "$0" ]; do sleep 0.05; done' "$1/checkpoints/learner-state.bin" ||
    fail "no learner state after 60 s"
}

# Fails when a process of the run was restarted: a restart hides a crash (a learner that
# segfaults mid-run still reaches the goal), so a test that kills nothing calls this at its end.
# Names each restarted process and how it died (from RUN/restarts: "TIME ROLE status CODE
# restart N", CODE 128 + the signal for a killed process) and shows the last lines of its log.
expect_no_restarts() {  # expect_no_restarts RUN_DIR
  local run=$1 time role word code word2 count how restarted=""
  local -A seen=()
  [ -f "$run/restarts" ] || fail "$run has no restarts file (not a launcher's run folder)"
  [ -s "$run/restarts" ] || return 0
  while read -r time role word code word2 count; do
    if [ "$code" -gt 128 ]; then
      how="was killed by signal $((code - 128)) (SIG$(kill -l $((code - 128)) 2>/dev/null || echo '?'))"
    else
      how="exited with status $code"
    fi
    seen[$role]=$((${seen[$role]:-0} + 1))
    echo "$role $how at $time (restart $count); the last lines of its log before it:" >&2
    # The lines before the launcher's message about this death (the role's k-th restart).
    awk -v k="${seen[$role]}" '/^launch: .*restarting it in/ && ++n == k {
        for (i = NR - 12; i < NR; i++) if (i > 0) print "  " line[i]; exit }
        { line[NR] = $0 }' "$run/logs/$role.log" >&2 || true
    restarted="$restarted${restarted:+, }$role ($how)"
  done < "$run/restarts"
  fail "processes of $run died and were restarted: $restarted"
}

# Waits (bounded) until every process of the run's pids file has ended (a zombie has ended).
expect_all_ended() {  # expect_all_ended RUN_DIR SECONDS
  local run=$1 limit=$2 role pid alive
  for _ in $(seq $((limit * 10))); do
    alive=""
    while read -r role pid; do
      if awk '$3 != "Z" { found = 1 } END { exit !found }' "/proc/$pid/stat" 2>/dev/null; then
        alive="$alive $role ($pid)"
      fi
    done < "$run/pids"
    [ -n "$alive" ] || return 0
    sleep 0.1
  done
  fail "processes of the run still alive $limit s later:$alive"
}

# After the launcher of RUN_DIR died mid-run (killed, hung up): every process stopped cleanly (the
# replay wrote its last snapshot, the learner its state), `launch.sh --stop` says the run is not
# going, and `launch.sh --resume` continues the run to the CartPole goal with no restart. Its
# output goes to RUN_DIR/../resumed.log.
expect_resumable_after_launcher_death() {  # expect_resumable_after_launcher_death RUN_DIR
  local run=$1 status
  grep -q "^replay: last snapshot written to " "$run/logs/replay.log" ||
    fail "the replay did not stop cleanly (no last snapshot): $(tail -3 "$run/logs/replay.log")"
  grep -q "^learner: stopped after " "$run/logs/learner.log" ||
    fail "the learner did not stop cleanly: $(tail -3 "$run/logs/learner.log")"
  status=0
  "$root/scripts/launch.sh" --stop "$run" > "$run/../stop.log" 2>&1 || status=$?
  [ "$status" -eq 1 ] && grep -q "is not going" "$run/../stop.log" ||
    fail "--stop after the launcher's end (status $status): $(cat "$run/../stop.log")"
  resume_to_goal "$run" "$run/../resumed.log"
  grep -q "resumed at update [1-9]" "$run/logs/learner.log" || fail "the learner did not resume"
  expect_no_restarts "$run"
}

# A copy of the checkout's layout in DIR for a launch that must not touch the checkout: its
# scripts (linked), its presets (copied, so that a test may edit them) and its own runs/, where
# default run folders go.
fake_root() {  # fake_root DIR
  mkdir -p "$1"
  ln -s "$root/scripts" "$1/scripts"
  cp -r "$root/configs" "$1/configs"
}

# The value of a '# key = value' line of a run's config.ini.
run_setting() { sed -n "s/^# $2 = //p" "$1/config.ini"; }

launch() { "$root/scripts/launch.sh" "$@" --no-setup --build-dir "$build_dir"; }

# Runs `launch ARGS...` to its end, its output to LOG; shows the last lines and fails unless it
# exited 0 (the goal reached).
launch_to_goal() {  # launch_to_goal LOG PRESET [LAUNCH OPTIONS...]
  local log=$1 status=0
  shift
  launch "$@" > "$log" 2>&1 || status=$?
  tail -20 "$log"
  [ "$status" -eq 0 ] || fail "launch exited with $status"
}

# Continues the run in RUN_DIR with `launch.sh --resume` (time budget 240 s), its output to LOG;
# shows the last lines and fails unless it exited 0 (the goal reached).
resume_to_goal() {  # resume_to_goal RUN_DIR LOG
  local status=0
  "$root/scripts/launch.sh" --resume "$1" --no-setup --build-dir "$build_dir" --time-budget 240 \
    > "$2" 2>&1 || status=$?
  tail -5 "$2"
  [ "$status" -eq 0 ] || fail "the resumed run exited with $status"
}

# The last value of FIELD in ROLE's rows of a run's metrics.jsonl (empty when it has none).
last_metric() {  # last_metric RUN_DIR ROLE FIELD
  grep -F "\"role\": \"$2\"," "$1/metrics.jsonl" 2>/dev/null | tail -1 |
    sed -n "s/.*\"$3\": \([-0-9.e+]*\)[,}].*/\1/p"
}

# The highest "update" of a run's eval.jsonl (-1 when it has none).
last_scored_update() {  # last_scored_update RUN_DIR
  { sed -n 's/.*"update": \([0-9]*\).*/\1/p' "$1/eval.jsonl" 2>/dev/null; echo -1; } | sort -n | tail -1
}

# Whether the numeric FIELD of every line of an eval.jsonl after its first N lines is at least
# the highest of those N: a resumed run carries on from where it stopped. (Within one part the
# lines are in scoring order, not always in update order: the evaluator scores superseded
# checkpoints later.) ON_DISK, a file of the checkpoint names in the run's folder at the
# resumption: those of them not scored in the first N lines are the earlier part's, which the
# resumed evaluator scores after the resumption, and their lines are not checked.
carries_on() {  # carries_on EVAL_JSONL N FIELD [ON_DISK]
  awk -v n="$2" -v on_disk="${4:-}" -F"\"$3\": " '
    BEGIN { if (on_disk != "") while ((getline name < on_disk) > 0) earlier[name] = 1 }
    { split($2, a, ","); v = a[1] + 0
      name = ""; if (match($0, /"checkpoint": "[^"]*"/)) name = substr($0, RSTART + 15, RLENGTH - 16) }
    NR <= n { delete earlier[name]; if (NR == 1 || v > top) top = v; next }
    name in earlier { next }
    v < top { print "'"$3"' " v " after " top " before the resumption"; bad = 1; exit }
    END { exit bad }' "$1"
}

# Fails when a process of the run reported a sanitizer finding in its log (ASan, LSan, UBSan or
# TSan, on a sanitizer build): the process aborted, and its restart would hide it.
expect_no_sanitizer_reports() {  # expect_no_sanitizer_reports RUN_DIR
  local pattern='^==[0-9]+==ERROR: (Address|Leak)Sanitizer|runtime error: |WARNING: ThreadSanitizer'
  local found
  found=$(grep -l -E "$pattern" "$1"/logs/*.log 2>/dev/null || true)
  [ -z "$found" ] || { grep -h -A30 -E "$pattern" $found | head -80 >&2; fail "sanitizer reports in" $found; }
}
