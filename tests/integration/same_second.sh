#!/usr/bin/env bash
# Two launches started in the same second (the default run folder's name has one-second
# resolution) get two run folders, each with its own config.ini, run id and processes; and a
# launcher cannot take a run folder another launcher holds (--resume of a going run).
source "$(dirname "$0")/lib.sh"
isolate "$@"
scratch
fake_root "$dir/root"
fake="$dir/root/scripts/launch.sh"
runs="$dir/root/runs"
# A launcher names its folder about a second after it starts, a time that depends on the
# machine's load: each attempt starts both at another point of the second (0.17 s further on), so
# that in one of them both name their folders inside one second, whatever that time is.
attempts=6
for attempt in $(seq 1 $attempts); do
  phase=$((attempt * 17 % 100))
  timeout 5 bash -c 'until c=$((10#$(date +%N | cut -c1-2))); [ "$c" -ge "$0" ] && [ "$c" -lt $(($0 + 5)) ]; do sleep 0.005; done' "$phase"
  for x in a b; do
    "$fake" cartpole --no-setup --build-dir "$build_dir" --actors 1 --goal 1000000 \
      --time-budget 60 > "$dir/$x.log" 2>&1 &
    eval "pid_$x=\$!"
  done
  wait_line "$dir/a.log" "running; logs in" 60
  wait_line "$dir/b.log" "running; logs in" 60
  folder_a=$(sed -n "s/^launch: run [0-9]* of 'cartpole' in \(.*\) (LCM port.*/\1/p" "$dir/a.log")
  folder_b=$(sed -n "s/^launch: run [0-9]* of 'cartpole' in \(.*\) (LCM port.*/\1/p" "$dir/b.log")
  echo "attempt $attempt (started at .$(printf %02d "$phase") s): $folder_a and $folder_b"
  [ -n "$folder_a" ] && [ -n "$folder_b" ] || fail "a launch did not name its folder"
  [ "$folder_a" != "$folder_b" ] || fail "both launches got $folder_a"
  # The one folder the same second gives, and one with a suffix.
  first=$(ls "$runs" | sort | head -1)
  if [ "$(ls "$runs" | sort | tr '\n' ' ')" = "$first $first-2 " ]; then break; fi
  echo "not in the same second ($(ls "$runs" | tr '\n' ' ')); again"
  for x in a b; do "$root/scripts/launch.sh" --stop "$(eval echo "\$folder_$x")" > /dev/null || true; done
  wait || true
  rm -rf "${runs:?}"/*
  [ "$attempt" -lt "$attempts" ] || fail "$attempts attempts, never two launches in one second"
done

# A launcher cannot take a folder another one holds.
set +e
timeout 20 "$fake" --resume "$folder_a" --no-setup --build-dir "$build_dir" > "$dir/locked.log" 2>&1
status=$?
set -e
cat "$dir/locked.log"
[ "$status" -eq 2 ] && grep -q "^launch: the run in $folder_a is going (launcher pid $pid_a)" "$dir/locked.log" ||
  fail "a second launcher on a going run: status $status"

for x in a b; do
  folder=$(eval echo "\$folder_$x")
  "$root/scripts/launch.sh" --stop "$folder" > "$dir/stop-$x.log" 2>&1 || fail "--stop $folder: $(cat "$dir/stop-$x.log")"
  id=$(sed -n "s/^launch: run \([0-9]*\) of .*/\1/p" "$dir/$x.log")
  [ "$(run_setting "$folder" run-id)" = "$id" ] || fail "$folder's config.ini has another run's id"
  grep -q "^actor-0: stopped" "$folder/logs/actor-0.log" || fail "$folder's actor did not run"
  expect_no_restarts "$folder"
done
wait || true
[ "$(run_setting "$folder_a" run-id)" != "$(run_setting "$folder_b" run-id)" ] || fail "one run id"
echo "PASS: two launches in one second got $(basename "$folder_a") and $(basename "$folder_b")"
