#!/usr/bin/env bash
# Starts lcm-spy on Java 17 with our message types, so that every channel of a run is decoded.
# (Debian's lcm-spy wrapper passes -Xincgc, which Java 17 refuses.)
#
# Usage: scripts/spy.sh [--run RUN_DIR | --lcm-url URL] [--bulk | --samples] [--build-dir DIR]
#                       [--print-url]
#   --run RUN_DIR   watch the run in RUN_DIR (reads its LCM URLs from RUN_DIR/config.ini)
#   --lcm-url URL   watch this URL (default: the processes' default main URL)
#   --bulk          watch the run's bulk port (weights) instead of the main one
#   --samples       watch the run's samples port (the replay's sample replies to the learner)
#   --print-url     print the URL it would watch, and exit
# lcm-spy's Java side ignores recv_buf_size; our chunks stay below 60 KB so that it sees them.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
run="" url="udpm://239.255.76.67:7667?ttl=0" key=lcm-url build_dir="$root/build" print=0
while [ $# -gt 0 ]; do
  case "$1" in
    --run) run="$2"; shift ;;
    --lcm-url) url="$2"; shift ;;
    --bulk) key=lcm-bulk-url ;;
    --samples) key=lcm-samples-url ;;
    --build-dir) build_dir="$2"; shift ;;
    --print-url) print=1 ;;
    -h|--help) awk 'NR > 1 && /^#/ { sub(/^# ?/, ""); print; next } NR > 1 { exit }' "$0"; exit 0 ;;
    *) echo "spy.sh: unknown option '$1'" >&2; exit 2 ;;
  esac
  shift
done
if [ -n "$run" ]; then
  [ -f "$run/config.ini" ] || { echo "spy.sh: no $run/config.ini: not a run folder" >&2; exit 2; }
  url=$(sed -n "s/^# $key = //p" "$run/config.ini")
  if [ -z "$url" ] && [ "$key" = lcm-samples-url ]; then
    # A run of an earlier version (no such line) has its samples where the launcher resumes it:
    # on multicast the port after the bulk port, through TCP hubs the bulk hub.
    url=$(sed -n "s/^# lcm-bulk-url = //p" "$run/config.ini")
    if [[ "$url" =~ ^(udpm://[^:]+:)([0-9]+)(.*)$ ]]; then
      url="${BASH_REMATCH[1]}$((BASH_REMATCH[2] + 1))${BASH_REMATCH[3]}"
    fi
  fi
  [ -n "$url" ] || { echo "spy.sh: no '# $key' line in $run/config.ini" >&2; exit 2; }
fi
if [ "$print" = 1 ]; then echo "$url"; exit 0; fi
jar="$build_dir/lcmtypes/rlmsg_types.jar"
[ -f "$jar" ] || { echo "spy.sh: $jar is missing: run scripts/setup.sh (needs a JDK)" >&2; exit 2; }
for j in /usr/share/java/lcm.jar /usr/share/java/jchart2d.jar; do
  [ -f "$j" ] || { echo "spy.sh: $j is missing: run scripts/setup.sh" >&2; exit 2; }
done
exec java -server -Djava.net.preferIPv4Stack=true -Xmx256m -Xms64m -ea \
  -cp "/usr/share/java/lcm.jar:/usr/share/java/jchart2d.jar:$jar" lcm.spy.Spy --lcm-url="$url"
