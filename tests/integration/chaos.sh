#!/usr/bin/env bash
# Kills at any moment: during one CartPole run, SIGKILL a random process (an actor, the replay,
# the learner, the evaluator) at random times, CHAOS_KILLS times (6): the first within 2 s of the
# first start (while the run is still starting), and some while the replay writes a snapshot, the
# learner a checkpoint or its state, or the evaluator its report (the test waits for the writer's
# temporary file and kills at once). Each kill waits until the process killed before it is back
# and ready (the run may reach its goal before the last kills, not before CHAOS_MIN_KILLS, 4). The
# run must still reach its goal, with the report whole, one restart per kill, no message dropped,
# no temporary file left behind, and no process of the run alive after it.
#
# Seeded: CHAOS_SEED (default 21) draws the victims, the moments and which kills aim at a write;
# the seed is printed at the start and in every failure, with the command that runs it again.
# What a kill meets inside the process (a write under way or not) depends on timing as well, and
# the test prints what each kill met.
source "$(dirname "$0")/lib.sh"
isolate "$@"
seed=${CHAOS_SEED:-21}
kills=${CHAOS_KILLS:-6}
# A run may reach its goal before the last kills (CartPole is quick on a quiet machine): it must
# not before this many.
min_kills=${CHAOS_MIN_KILLS:-4}
again="CHAOS_SEED=$seed ctest --test-dir $build_dir -R integration.chaos --output-on-failure"
fail() { echo "FAIL: $* (chaos seed $seed; again: $again)" >&2; exit 1; }
scratch
run="$dir/run"
roles=(replay learner evaluator actor-0 actor-1)
# What each writer leaves while it writes: PATH.tmp.<pid of the writer> (common/atomic_file.h).
declare -A writes=([replay]="$run/replay-snapshot.bin" [learner]="$run/checkpoints/"
                   [evaluator]="$run/report/")
echo "chaos seed $seed, $kills kills (again: $again)"

# The schedule, drawn before anything runs: for each kill a victim, a wait before it (ms), and
# whether it aims at a write. Every kind of process is killed: the roles in a random order, then
# random ones. Of kills 2..N, each writer aims at a write with odds 2 in 3, at least two do (the
# order puts at least two writers there), and those come first, before the goal can end the run.
RANDOM=$seed
order=("${roles[@]}")
for ((i = ${#order[@]} - 1; i > 0; i--)); do
  j=$((RANDOM % (i + 1)))
  swap=${order[i]} order[i]=${order[j]} order[j]=$swap
done
victims=() delay_ms=() at_write=()
for ((k = 0; k < kills; k++)); do
  victims[k]=${order[k]:-${roles[RANDOM % ${#roles[@]}]}}
  delay_ms[k]=$((k == 0 ? 200 + RANDOM % 1800 : 100 + RANDOM % 900))
  at_write[k]=0
  if ((k > 0 && RANDOM % 3 > 0)) && [ -n "${writes[${victims[k]}]:-}" ]; then at_write[k]=1; fi
done
for ((n = 0, k = 1; k < kills; k++)); do n=$((n + at_write[k])); done
for ((k = 1; k < kills && n < 2; k++)); do
  if ((at_write[k] == 0)) && [ -n "${writes[${victims[k]}]:-}" ]; then
    at_write[k]=1 n=$((n + 1))
  fi
done
# The kills aimed at a write first (a stable partition of kills 2..N).
first=() rest=()
for ((k = 1; k < kills; k++)); do
  if ((at_write[k])); then first+=("${victims[k]}"); else rest+=("${victims[k]}"); fi
done
for ((k = 1; k < kills; k++)); do
  at_write[k]=$((k <= ${#first[@]}))
  victims[k]=${first[k - 1]:-${rest[k - 1 - ${#first[@]}]}}
done
plan=""
for ((k = 0; k < kills; k++)); do
  mark=""
  ((at_write[k] == 0)) || mark=" writing"
  plan="$plan${plan:+, }${delay_ms[k]} ms, ${victims[k]}$mark"
done
echo "the plan: $plan"

now_ms() { echo $(($(date +%s%N) / 1000000)); }
start_ms=$(now_ms)
since() { awk -v ms=$(($(now_ms) - $1)) 'BEGIN { printf "%.1f s", ms / 1000 }'; }
elapsed() { since "$start_ms"; }
pid_of() { awk -v r="$1" '$1 == r {p = $2} END {print p}' "$run/pids" 2>/dev/null; }
starts_of() { lines "$run/pids" "^$1 "; }
alive() { awk '$3 != "Z" { found = 1 } END { exit !found }' "/proc/$1/stat" 2>/dev/null; }
going() { kill -0 "$launch_pid" 2>/dev/null; }

# A process may be killed several times in a row: the launcher must not give up on it. A snapshot
# every second, so that kills find one being written; a tenth of the preset's learning rate, so
# that CartPole is not solved before the kills are made (it can be within 10 s).
launch cartpole --out "$run" --actors 2 --seed 7 --time-budget 240 --max-restarts "$kills" \
  --replay-args "--snapshot-every 1" --learner-args "--learning-rate 0.0001" \
  > "$dir/launch.log" 2>&1 &
launch_pid=$!

# Waits (bounded) until ROLE's next start (its START-th) is ready: its pid listed again, and the
# last line of its log of either kind a ready line of its own (not the launcher's restart line).
wait_back() {  # wait_back ROLE START
  local until=$((SECONDS + 60))
  until [ "$(starts_of "$1")" -ge "$2" ] &&
    grep "^$1: ready\|^launch: $1 " "$run/logs/$1.log" | tail -1 | grep -q "^$1: ready"; do
    going || return 0  # the run reached its goal meanwhile
    ((SECONDS < until)) || fail "$1 was not started again and ready within 60 s"
    sleep 0.05
  done
}

# Polls (tight, bounded) for a temporary file of ROLE's writer; prints its path.
find_write() {  # find_write ROLE SECONDS
  local prefix=${writes[$1]} until=$((SECONDS + $2)) f
  while ((SECONDS < until)) && going; do
    for f in "$prefix"*.tmp.*; do
      [ -e "$f" ] && { echo "$f"; return 0; }
    done
  done
  return 1
}

during_write=0 made=0 early=""
for ((k = 0; k < kills; k++)); do
  victim=${victims[k]}
  if ((k == 0)); then
    # Within 2 s of the first start (or at its own start, when it starts later), while the run
    # is still starting.
    timeout 60 bash -c 'until [ -s "$0" ]; do sleep 0.01; done' "$run/pids" ||
      fail "no process started within 60 s"
    first_ms=$(now_ms)
    sleep "$(awk -v ms="${delay_ms[0]}" 'BEGIN { print ms / 1000 }')"
    timeout 60 bash -c 'until grep -q "^$1 " "$0"; do sleep 0.01; done' "$run/pids" "$victim" ||
      fail "$victim did not start within 60 s"
  else
    sleep "$(awk -v ms="${delay_ms[k]}" 'BEGIN { print ms / 1000 }')"
  fi
  going || break
  starts=$(starts_of "$victim")
  pid=$(pid_of "$victim")
  [ -n "$pid" ] || fail "no pid for $victim"
  what=""
  # Until a kill has cut a write short, every kill of a writer aims at a write (a retry).
  if ((k > 0 && during_write == 0)) && [ -n "${writes[$victim]:-}" ]; then at_write[k]=1; fi
  if ((at_write[k])); then
    # Kill as soon as a temporary file of its writer shows.
    if tmp=$(find_write "$victim" 20); then
      # The replay writes from a forked child: the file's suffix is the writer's pid.
      writer=${tmp##*.tmp.}
      [[ $writer =~ ^[0-9]+$ ]] || writer=$pid
      kill -KILL "$pid"
      # Once the writer is gone, its file is still there only when the kill cut the write short.
      for _ in $(seq 1000); do alive "$writer" || break; sleep 0.01; done
      ! alive "$writer" || fail "the writer $writer of $victim outlived it by 10 s"
      if [ -e "$tmp" ]; then
        what="during a write of ${tmp#"$run"/}"
        during_write=$((during_write + 1))
      else
        what="just after a write of ${tmp#"$run"/} ended"
      fi
    else
      going || break
      what="(no write seen within 20 s)"
    fi
  fi
  alive "$pid" && kill -KILL "$pid"
  made=$((made + 1))
  [ -n "$early" ] || early="$victim at $(since "$first_ms")"
  echo "kill $made at $(elapsed): $victim (pid $pid)${what:+ $what}"
  # Back and ready before the next kill, so that each kill is one restart.
  wait_back "$victim" $((starts + 1))
done
echo "$made of $kills kills made; $during_write during a write;" \
  "the first: $early after the first start"

set +e
wait "$launch_pid"
status=$?
set -e
end=$(elapsed)
tail -4 "$dir/launch.log"
[ "$status" -eq 0 ] || fail "launch exited with $status"
grep -q "goal of .* reached" "$dir/launch.log" || fail "no goal line"
((made >= min_kills)) ||
  fail "the run reached its goal after $made kills (at least $min_kills expected)"
((during_write >= 1)) || fail "no kill landed during a write"

# One restart per kill, each by SIGKILL, counted on the progress line and in the report.
restarts=$(wc -l < "$run/restarts")
[ "$restarts" -eq "$made" ] || fail "$restarts restarts for $made kills: $(cat "$run/restarts")"
[ "$(grep -c " status 137 restart " "$run/restarts")" -eq "$made" ] ||
  fail "a restart was not of a SIGKILL: $(cat "$run/restarts")"
grep -q "restarts $made" "$run/logs/monitor.log" ||
  fail "the progress line does not count $made restarts"

# The report is whole: every section of a CartPole run, the goal reached, the restarts listed,
# every picture and video it shows on disk, and the page complete.
report="$run/report/index.html"
[ -s "$report" ] || fail "no report"
for section in Summary "Learning curves" Training "Greedy policy" Checkpoints Restarts \
  "Run config"; do
  grep -q "<h2>$section</h2>" "$report" || fail "the report has no section $section"
done
grep -q 'badge yes">reached' "$report" || fail "the report does not say the goal was reached"
grep -q "$made process restarts" "$report" || fail "the report does not list the $made restarts"
tail -1 "$report" | grep -q '^</html>$' || fail "the report ends early"
for src in $(grep -o 'src="[^"]*"' "$report" | sed 's/src="\(.*\)"/\1/' | sort -u); do
  [ -s "$run/report/$src" ] || fail "the report shows $src, which is missing or empty"
done
awk '!/^\{.*\}$/ { print "line " NR ": " $0; bad = 1 } END { exit bad }' "$run/eval.jsonl" ||
  fail "eval.jsonl has a torn line"

# Nothing dropped or lost: no process refused a message of another (a state restored wrongly
# after a restart shows as messages refused as invalid, stale or replayed), and the replay's last
# line counts none.
if grep -h "dropped a" "$run"/logs/*.log | grep -v '^launch:' | head -5 | grep .; then
  fail "processes dropped messages"
fi
last=$(grep '^replay: size' "$run/logs/replay.log" | tail -1)
echo "$last"
echo "$last" | grep -q " dropped 0 lost 0 " || fail "the replay dropped or lost messages: $last"
# Nor lost (a gap in a live sender's sequence) or dropped by any process: the monitor's last
# progress line sums every process's counts.
last=$(grep '^\[ *[0-9.]*s\]' "$run/logs/monitor.log" | tail -1)
echo "$last"
echo "$last" | grep -q "  lost 0  dropped 0 " || fail "messages lost or dropped: $last"

# Writers killed mid-write leave temporary files: their next start removes them.
left=$(find "$run" -name '*.tmp.*' | sed "s|^$run/||" | tr '\n' ' ')
[ -z "$left" ] || fail "temporary files left in the run folder: $left"
# No process of the run outlives it (every pid it listed, and whatever names the run folder).
expect_all_ended "$run" 10
others=$(pgrep -f -- "$run" || true)
[ -z "$others" ] ||
  fail "processes of the run still alive: $(ps -o pid,args -p "$(echo $others | tr ' ' ,)")"
echo "PASS: chaos seed $seed: $made of $kills kills ($during_write during a write," \
  "the first $early in), the goal reached in $end, the report whole"
