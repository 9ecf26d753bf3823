#!/usr/bin/env bash
# Starts a whole run: the replay daemon, the learner, the evaluator and N actors, talking over
# LCM, with a live progress line; installs and builds what is missing first. The run itself is
# the launcher's (build/bin/launcher, launch/README.md): it checks its input before anything
# starts, supervises every process (restarts, readiness, a clean stop) and leaves none behind
# however it ends. Exit status: 0 goal reached, 1 not reached, 2 bad input or a process that
# failed at its start, 129 hang-up, 130 stopped (Ctrl-C, SIGTERM, --stop).
#
# Usage: scripts/launch.sh PRESET [options]
#        scripts/launch.sh --resume RUN_DIR [options]
#        scripts/launch.sh --stop RUN_DIR
#   --build-dir DIR        where the binaries are built (default build)
#   --no-setup             do not install or build (use the binaries as they are)
#   every other option is the launcher's: scripts/launch.sh --help lists them
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build_dir="$root/build" setup=1 help=0
args=()
while [ $# -gt 0 ]; do
  case "$1" in
    --build-dir)
      [ $# -ge 2 ] || { echo "launch: --build-dir needs a value" >&2; exit 2; }
      build_dir=$2
      shift ;;
    --no-setup) setup=0 ;;
    -h|--help) help=1; args+=("$1") ;;
    *) args+=("$1") ;;
  esac
  shift
done
# Stopping a run or reading the help builds nothing.
if [ "$help" -eq 1 ] || [ "${args[0]:-}" = "--stop" ]; then
  setup=0
fi
if [ "$setup" -eq 1 ]; then
  "$root/scripts/setup.sh" --build-dir "$build_dir"
fi
launcher="$build_dir/bin/launcher"
if [ ! -x "$launcher" ]; then
  if [ "$help" -eq 1 ]; then
    awk 'NR > 1 && /^#/ { sub(/^# ?/, ""); print; next } NR > 1 { exit }' "$0"
    echo "(build the launcher to see its options: scripts/setup.sh)"
    exit 0
  fi
  echo "launch: $launcher is missing (build first, or drop --no-setup)" >&2
  exit 2
fi
exec "$launcher" --root "$root" ${args[@]+"${args[@]}"}
