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

# A fresh scratch folder, removed on exit unless RL_KEEP is set.
scratch() {
  local d
  d=$(mktemp -d "${TMPDIR:-/tmp}/rl-it-XXXXXX")
  [ -n "${RL_KEEP:-}" ] || trap "rm -rf '$d'" EXIT
  echo "$d"
}

# Waits (bounded) until FILE has a line matching PATTERN.
wait_line() {  # wait_line FILE PATTERN TIMEOUT_SECONDS
  local file=$1 pattern=$2 limit=$3
  timeout "$limit" bash -c 'until grep -q -- "$1" "$0" 2>/dev/null; do sleep 0.05; done' "$file" "$pattern" ||
    fail "no line matching '$pattern' in $file within $limit s"
}

# The value of a '# key = value' line of a run's config.ini.
run_setting() { sed -n "s/^# $2 = //p" "$1/config.ini"; }

launch() { "$root/scripts/launch.sh" "$@" --no-setup --build-dir "$build_dir"; }
