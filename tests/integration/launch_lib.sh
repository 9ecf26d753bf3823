# Helpers of the tests that kill or stop processes of a running CartPole launch (sourced after
# lib.sh).

# Starts `launch.sh cartpole --out $dir/run LAUNCH_OPTIONS...` in the background, its output to
# LOG, and waits until the run is going; sets launch_pid to the pid of launch.sh (which execs the
# launcher: the pid to signal or wait for).
start_cartpole() {  # start_cartpole LOG [LAUNCH OPTIONS...]
  local log=$1
  shift
  "$root/scripts/launch.sh" cartpole --no-setup --build-dir "$build_dir" --out "$dir/run" "$@" \
    > "$log" 2>&1 &
  launch_pid=$!
  wait_line "$log" "running; logs in" 60
}

# Waits for the launch of start_cartpole to end, sets status to its exit status, and shows the
# last lines of LOG.
wait_launch() {  # wait_launch LOG
  status=0
  wait "$launch_pid" || status=$?
  tail -8 "$1"
}

# Sends SIGNAL (KILL unless given) to the newest process of ROLE in $dir/run/pids; sets victim
# to its pid.
kill_role() {  # kill_role ROLE [SIGNAL]
  victim=$(awk -v r="$1" '$1 == r {p = $2} END {print p}' "$dir/run/pids")
  [ -n "$victim" ] || fail "no pid for $1"
  kill -"${2:-KILL}" "$victim"
  echo "sent SIG${2:-KILL} to $1 (pid $victim)"
}
