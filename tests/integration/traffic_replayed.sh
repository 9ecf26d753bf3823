#!/usr/bin/env bash
# Recorded traffic played back into the live run it came from changes nothing, also after the
# receiver was killed and restarted: a CartPole run records its main port (launch.sh --record)
# and, here, its samples port too; lcm-logplayer plays the recordings back onto the run's ports.
#   1. Into the live run, with its actors stopped: the replay and the evaluator drop every
#      recorded message of their channels as replayed (exactly as many as the file holds), the
#      replay inserts nothing, and no lost count moves (tools/inject.cc --replayed-log).
#   2. The same after SIGKILL of the replay, restarted by the supervisor from a snapshot written
#      after the recording's end: the restarted replay loads the last position of every sender
#      with it, so it still refuses the recording (replayed, or stale once older than its window)
#      and stores none of it.
#   3. The recorded sample replies after SIGKILL of the learner, restarted from its state file,
#      with the replay stopped so that the learner hears no live reply: it drops them as replayed
#      and trains on none (its update count stands still); without the positions it took the
#      recorded replies to its first requests, whose ids a restarted learner uses again.
# Then the run goes on, and launch.sh --stop stops it cleanly.
source "$(dirname "$0")/lib.sh"
isolate "$@"
scratch
command -v lcm-logplayer >/dev/null || fail "lcm-logplayer is missing (liblcm-bin)"
# The samples port is recorded from before the run starts, so that the recording holds the
# replies to the learner's first requests (ids 0, 1, ...).
# Below Linux's ephemeral ports (32768 on), where no sending socket can hold one of them.
port=$((20000 + 3 * (RANDOM % 4255)))
bulk_url="udpm://239.255.76.67:$((port + 1))?ttl=0&recv_buf_size=4194304"
samples_url="udpm://239.255.76.67:$((port + 2))?ttl=0&recv_buf_size=4194304"
lcm-logger --quiet --lcm-url="$samples_url" "$dir/samples.lcmlog" > "$dir/samples-logger.log" 2>&1 &
samples_logger=$!
set -m
launch cartpole --out "$dir/run" --actors 2 --seed 4 --goal 1000000 --time-budget 300 --record \
  --port "$port" --replay-args "--snapshot-every 1" > "$dir/launch.log" 2>&1 &
launch_pid=$!
set +m
wait_line "$dir/launch.log" "running; logs in" 60
run="$dir/run"
url=$(run_setting "$run" lcm-url)
[ "$(run_setting "$run" lcm-bulk-url)" = "$bulk_url" ] || fail "the run's bulk port is not $bulk_url"
[ "$(run_setting "$run" lcm-samples-url)" = "$samples_url" ] ||
  fail "the run's samples port is not $samples_url"
# Traffic of every kind, a checkpoint and its evaluation included.
wait_line "$run/eval.jsonl" '"checkpoint"' 90

pid_of() { awk -v r="$1" '$1 == r {p = $2} END {print p}' "$run/pids"; }
# The learner's newest metrics: field NAME of its last line in metrics.jsonl.
learner_rows='"role": "learner"'
learner_metric() {
  grep "$learner_rows" "$run/metrics.jsonl" | tail -1 | grep -Eo "\"$1\": [0-9.e+]+" |
    grep -Eo '[0-9.e+]+$'
}
learner_updates_at_least() { [ "$(learner_metric updates)" -ge "$1" ]; }
# Waits (bounded) until COMMAND succeeds.
wait_for() {  # wait_for TIMEOUT_SECONDS WHAT COMMAND...
  local limit=$1 what=$2 end=$((SECONDS + $1))
  shift 2
  until "$@"; do
    [ "$SECONDS" -lt "$end" ] || fail "$what within $limit s"
    sleep 0.05
  done
}
# Plays the main-port recording back while inject checks that the replay and the evaluator
# refuse all of it and that nothing changes (the actors are stopped). Each call logs to a file of
# its own: the background inject truncates its log only once it starts, so a reused file would
# still hold the last call's "ready for playback" and the playback would begin before inject
# took its baseline.
plays=0
play_back() {  # play_back WHAT
  local log="$dir/inject-$((plays += 1)).log"
  "$bin/inject" --replayed-log "$dir/main.lcmlog" --run-id "$(run_setting "$run" run-id)" \
    --key-file "$run/key" --lcm-url "$url" --lcm-bulk-url "$bulk_url" --lcm-samples-url "$samples_url" --timeout 60 \
    > "$log" 2>&1 &
  local inject_pid=$! inject_status=0
  wait_line "$log" "ready for playback" 60
  lcm-logplayer --speed=2 --lcm-url="$url" "$dir/main.lcmlog" > "$dir/player.log" 2>&1 ||
    fail "lcm-logplayer failed: $(tail -3 "$dir/player.log")"
  wait "$inject_pid" || inject_status=$?
  grep -v "^\[inject\]" "$log"
  [ "$inject_status" -eq 0 ] || fail "$1 took recorded traffic, or it changed the run"
}

# --- 1. The live run ----------------------------------------------------------------------
actors=$(awk '$1 ~ /^actor-/ {p[$1] = $2} END {for (a in p) print p[a]}' "$run/pids")
[ -n "$actors" ] || fail "no actor in $run/pids"
# shellcheck disable=SC2086
kill -STOP $actors
# What the logger has written so far (the live file grows while it plays, with the played
# messages too).
cp "$run/lcm-log/main.lcmlog.0" "$dir/main.lcmlog"
play_back "the live run"
grep -q "dropped a replayed message" "$run/logs/replay.log" || fail "the replay logged no replayed drop"

# --- 2. The replay, restarted -------------------------------------------------------------
written="^replay: snapshot [0-9]* written"
snapshots=$(lines "$run/logs/replay.log" "$written")
# Two more snapshots: the second began after the recording's end, so it holds every position.
wait_lines "$run/logs/replay.log" "$written" $((snapshots + 2)) 30
kill -KILL "$(pid_of replay)"
wait_line "$run/logs/replay.log" "^replay: snapshot .* loaded (" 30
grep "^replay: snapshot .* loaded (" "$run/logs/replay.log" | tail -1
play_back "the restarted replay"
# shellcheck disable=SC2086
kill -CONT $actors
grep -q " replay status 137 restart 1$" "$run/restarts" || fail "the replay was not restarted"

# --- 3. The learner, restarted ------------------------------------------------------------
# Training again, with a newer learner state (a checkpoint every 500 updates).
updates=$(learner_metric updates)
wait_for 60 "1000 more updates" learner_updates_at_least $((updates + 1000))
replay_pid=$(pid_of replay)
kill -STOP "$replay_pid"
kill -INT "$samples_logger"
wait "$samples_logger" || true
kill -KILL "$(pid_of learner)"
wait_lines "$run/logs/learner.log" "^learner: ready" 2 30
# Its first stats, then what it has trained and refused so far.
rows=$(lines "$run/metrics.jsonl" "$learner_rows")
wait_lines "$run/metrics.jsonl" "$learner_rows" $((rows + 2)) 10
before=$(learner_metric updates)
refused_before=$(learner_metric replayed)
lcm-logplayer --speed=20 --regexp=RL_SAMPLES --lcm-url="$samples_url" "$dir/samples.lcmlog" \
  > "$dir/samples-player.log" 2>&1 ||
  fail "lcm-logplayer failed: $(tail -3 "$dir/samples-player.log")"
rows=$(lines "$run/metrics.jsonl" "$learner_rows")
wait_lines "$run/metrics.jsonl" "$learner_rows" $((rows + 2)) 10
after=$(learner_metric updates)
refused_after=$(learner_metric replayed)
kill -CONT "$replay_pid"
echo "learner: updates $before -> $after while the recorded replies played; replayed" \
  "$refused_before -> $refused_after"
[ "$after" = "$before" ] || fail "the restarted learner trained on recorded replies"
awk -v a="$refused_after" -v b="$refused_before" 'BEGIN {exit !(a > b)}' ||
  fail "the restarted learner counted no recorded reply as replayed"
grep -q " learner status 137 restart 1$" "$run/restarts" || fail "the learner was not restarted"

while read -r role pid; do
  kill -0 "$pid" 2>/dev/null || fail "$role (pid $pid) died"
done < <(awk '{p[$1] = $2} END {for (r in p) print r, p[r]}' "$run/pids")
# Stopped from outside, as a run in the background or in another terminal is.
"$root/scripts/launch.sh" --stop "$run" > "$dir/stop.log" 2>&1 || fail "launch.sh --stop: $(cat "$dir/stop.log")"
grep -q "^launch: stopped" "$dir/stop.log" || fail "launch.sh --stop did not wait for the stop"
while read -r role pid; do
  kill -0 "$pid" 2>/dev/null && fail "$role (pid $pid) was still running when --stop returned"
done < "$run/pids"
set +e
wait "$launch_pid"
status=$?
set -e
[ "$status" -eq 130 ] || fail "launch exited with $status after --stop, expected 130"
set +e
"$root/scripts/launch.sh" --stop "$run" > "$dir/stop2.log" 2>&1
status=$?
set -e
[ "$status" -eq 1 ] && grep -q "is not going" "$dir/stop2.log" ||
  fail "a second --stop did not say the run is not going (status $status): $(cat "$dir/stop2.log")"
echo "PASS: recordings played back into their run, live and after restarts of the replay and the" \
  "learner, were refused and changed nothing"
