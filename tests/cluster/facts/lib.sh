# Sourced by the batch script of the facts (FACTS, the shared folder, and FACTS_LOG come with its
# environment). log: the experiment's log; r MSG: a line of the batch script in it.
log=$FACTS/$FACTS_LOG.log
touch "$log"
read -r host < /proc/sys/kernel/hostname
r() { echo "$EPOCHREALTIME batch@$host $*" >> "$log"; }
# srun of one task on one node in the background, as a launcher would start it (SIGINT and
# SIGQUIT not ignored, which a script's background jobs otherwise are); its pid in $p.
bg_step() {  # bg_step NODE CMD...
  perl -e '$SIG{INT} = "DEFAULT"; $SIG{QUIT} = "DEFAULT"; exec @ARGV' \
    srun --overlap --nodes=1 --ntasks=1 --nodelist="$@" &
  p=$!
}
# Tells facts.sh that the job's probes are up.
ready() { r "ready (job $SLURM_JOB_ID, restart ${SLURM_RESTART_COUNT:-0})"; }
# Waits until NAME's probe has started.
started() { timeout 20 bash -c "until grep -q ' $1@.* start$' '$log'; do sleep 0.05; done"; }
# Waits for a background srun, through signals trapped meanwhile; its status in $rc.
wait_srun() { while :; do wait "$1"; rc=$?; [ $rc -gt 128 ] && kill -0 "$1" 2> /dev/null && continue; break; done; }
# Runs CMD with a bound; logs its status, how long it took and its output.
timed() {  # timed WHAT SECONDS CMD...
  local what=$1 limit=$2 t0=$EPOCHREALTIME out
  shift 2
  out=$(timeout "$limit" "$@" 2>&1); rc=$?
  r "$what: rc=$rc after $(awk -v a="$t0" -v b="$EPOCHREALTIME" 'BEGIN { printf "%.1f", b - a }') s: $(echo "$out" | tr '\n' ' ' | cut -c1-300)"
}
