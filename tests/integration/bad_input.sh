#!/usr/bin/env bash
# Bad launch input gets one clear error (exit 2) before anything starts: no process and no run
# folder. Numbers that are none or out of range, a run folder in a place that cannot hold one,
# and presets with a misspelled section or key; every preset of the checkout passes the same
# checks. And a preset's inline '# comment' after actors or goal is no part of the value (the
# processes read it so too). The learner's command line follows its list of algorithms.
source "$(dirname "$0")/lib.sh"
isolate "$@"
scratch
fake_root "$dir/root"
fake="$dir/root/scripts/launch.sh"
n=0
# Runs the launch with ARGS and expects exit status 2 within 20 s, a message matching PATTERN and
# no run folder (neither --out's nor a default one).
expect_refused() {  # expect_refused PATTERN ARGS...
  local pattern=$1 status
  shift
  n=$((n + 1))
  set +e
  timeout 20 "$fake" "$@" --no-setup --build-dir "$build_dir" > "$dir/refused-$n.log" 2>&1
  status=$?
  set -e
  echo "[$*] -> $status: $(cat "$dir/refused-$n.log")"
  [ "$status" -eq 2 ] || fail "launch $* exited with $status, not 2"
  grep -q -- "$pattern" "$dir/refused-$n.log" || fail "launch $* did not say '$pattern'"
  [ "$(wc -l < "$dir/refused-$n.log")" -eq 1 ] || fail "launch $* said more than one line"
  [ -z "$(ls -A "$dir/root/runs" 2>/dev/null)" ] || fail "launch $* made a run folder: $(ls "$dir/root/runs")"
}

expect_refused "^launch: --time-budget must be a positive number of seconds, not '-5'" cartpole --time-budget -5
expect_refused "^launch: --time-budget must be a positive number of seconds, not 'soon'" cartpole --time-budget soon
expect_refused "^launch: --time-budget must be a positive number of seconds, not '0'" cartpole --time-budget 0
expect_refused "^launch: --actors must be a whole number" cartpole --actors 2.5
expect_refused "^launch: --seed must be a whole number, not '-1'" cartpole --seed -1
expect_refused "^launch: --goal must be a number" cartpole --goal high
expect_refused "^launch: --record-mb must be a whole number of at least 8" cartpole --record --record-mb 0
expect_refused "^launch: cannot create the run folder /sys/rl-run/run: " cartpole --out /sys/rl-run/run
[ ! -e "$dir/root/runs" ] || [ -z "$(ls -A "$dir/root/runs")" ] || fail "a run folder was made"

# Misspelled sections and keys, top-level and in a section.
ini="$dir/root/configs/typo.ini"
{ cat "$root/configs/cartpole.ini"; printf '[lerner]\nlearning-rate = 0.001\n'; } > "$ini"
expect_refused "^launch: preset $ini: unknown section \[lerner\] (key 'learning-rate')" typo
{ printf 'leraning-rate = 0.001\n'; cat "$root/configs/cartpole.ini"; } > "$ini"
expect_refused "^launch: preset $ini: unknown top-level key 'leraning-rate'" typo
sed 's/^learning-rate = /leraning-rate = /' "$root/configs/cartpole.ini" > "$ini"
grep -q '^leraning-rate' "$ini" || fail "the preset has no learning-rate to misspell"
expect_refused "^launch: preset $ini: unknown key 'leraning-rate' in section \[learner\]" typo
expect_refused "^launch: no preset 'cartpol'" cartpol

# Every preset of the checkout passes the same checks (a dry run starts and creates nothing).
for ini in "$root"/configs/*.ini; do
  preset=$(basename "$ini" .ini)
  launch "$preset" --dry-run --out "$dir/dry" > "$dir/dry-$preset.log" 2>&1 ||
    fail "the preset $preset is refused: $(cat "$dir/dry-$preset.log")"
  grep -q "^learner: .*/learner --config $dir/dry/config.ini " "$dir/dry-$preset.log" ||
    fail "the dry run of $preset shows no learner: $(cat "$dir/dry-$preset.log")"
done
[ ! -e "$dir/dry" ] || fail "a dry run made its run folder"

# The learner's options come from its list of algorithms (learner/algorithms.h): each has a
# section of the help, an unknown one is refused naming the known ones, and an option of an
# algorithm the run did not choose is refused, not ignored (exit 2, one line, before any bus).
learner_refuses() {  # learner_refuses PATTERN ARGS...
  local pattern=$1 status
  shift
  set +e
  timeout 20 "$build_dir/bin/learner" "$@" > "$dir/learner.log" 2>&1
  status=$?
  set -e
  echo "learner $* -> $status: $(cat "$dir/learner.log")"
  [ "$status" -eq 2 ] || fail "learner $* exited with $status, not 2"
  grep -q -- "$pattern" "$dir/learner.log" || fail "learner $* did not say '$pattern'"
  [ "$(wc -l < "$dir/learner.log")" -eq 1 ] || fail "learner $* said more than one line"
}
learner_refuses "^learner: error: algorithm must be one of dqn, td3, not 'sac'$" --algorithm sac
learner_refuses "^learner: error: option --learning-rate does not apply: algorithm is td3, and it is an option of dqn$" \
  --algorithm td3 --learning-rate 0.01
learner_refuses "^learner: error: option --policy-delay does not apply: algorithm is dqn, and it is an option of td3$" \
  --policy-delay 3
# The evaluator refuses an eval-env whose observations or actions are not the run's env's (one
# line, exit 2, no folder): its networks could score none of the run's checkpoints.
car="CarRacing-v3+pixels(skip=5,stack=2,off-track=1"
set +e
timeout 20 "$build_dir/bin/evaluator" --env "$car,pedals=1)" --eval-env "CarRacing-v3+pixels(skip=5,stack=2)" \
  --out "$dir/eval" > "$dir/evaluator.log" 2>&1
status=$?
set -e
[ "$status" -eq 2 ] || fail "the evaluator took an eval-env without the run's pedals ($status)"
grep -q "^evaluator: error: eval-env CarRacing-v3+pixels(skip=5,stack=2) does not take the observations and actions of the run's env $car,pedals=1)$" \
  "$dir/evaluator.log" || fail "the evaluator did not say why: $(cat "$dir/evaluator.log")"
[ "$(wc -l < "$dir/evaluator.log")" -eq 1 ] || fail "the evaluator said more than one line"
[ ! -e "$dir/eval" ] || fail "the refused evaluator made its folder"
"$build_dir/bin/learner" --help > "$dir/learner-help.log"
for section in "Options of dqn" "Options of td3"; do
  grep -q "^$section" "$dir/learner-help.log" || fail "the learner's help has no '$section'"
done
grep -q "^  --algorithm .*dqn: for discrete" "$dir/learner-help.log" ||
  fail "the learner's help does not list dqn under --algorithm"

# Inline comments after actors and goal: the run starts with 1 actor and the goal 1000000.
sed -e 's/^\[actor\]$/actors = 1   # one actor\n[actor]/' \
    -e 's/^goal = 475$/goal = 1000000  # out of reach/' "$root/configs/cartpole.ini" > "$dir/root/configs/commented.ini"
grep -q '^actors = 1   # one actor' "$dir/root/configs/commented.ini" || fail "no commented actors line"
set +e
"$fake" commented --no-setup --build-dir "$build_dir" --out "$dir/commented" --time-budget 4 \
  > "$dir/commented.log" 2>&1
status=$?
set -e
tail -3 "$dir/commented.log"
[ "$status" -eq 1 ] || fail "the commented preset's run exited with $status (expected 1: budget spent)"
grep -q '^# actors = 1 (of 1), seed = 1, goal = 1000000, ' "$dir/commented/config.ini" ||
  fail "the run did not read actors and goal: $(grep '^# actors' "$dir/commented/config.ini")"
grep -q "goal of 1000000 not reached" "$dir/commented.log" || fail "no goal line"
expect_no_restarts "$dir/commented"
echo "PASS: bad launch input refused before anything started; inline comments read as the processes do; the learner's options follow its algorithms"
