#!/usr/bin/env bash
# scripts/spy.sh's choice of URL from a run folder's header: each port's own line, and for the
# samples port of a run of an earlier version (no such line) the port after the bulk port on
# multicast, the bulk hub through TCP. Usage: spy_url.sh SPY_SCRIPT
set -euo pipefail
spy=$1
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
fail() { echo "FAIL: $*"; exit 1; }
expect() {  # expect WANT ARGS...
  local want=$1 got
  shift
  got=$(bash "$spy" --print-url "$@") || fail "spy.sh $* failed"
  [ "$got" = "$want" ] || fail "spy.sh $*: '$got', not '$want'"
}
mkdir "$dir/new" "$dir/old" "$dir/tcp" "$dir/none"
cat > "$dir/new/config.ini" <<'LINES'
# lcm-url = udpm://239.255.76.67:20000?ttl=0
# lcm-bulk-url = udpm://239.255.76.67:20001?ttl=0
# lcm-samples-url = udpm://239.255.76.67:20002?ttl=0
LINES
grep -v samples "$dir/new/config.ini" > "$dir/old/config.ini"
cat > "$dir/tcp/config.ini" <<'LINES'
# lcm-url = tcpq://10.0.0.5:20000
# lcm-bulk-url = tcpq://10.0.0.5:20001
LINES
expect "udpm://239.255.76.67:20000?ttl=0" --run "$dir/new"
expect "udpm://239.255.76.67:20001?ttl=0" --run "$dir/new" --bulk
expect "udpm://239.255.76.67:20002?ttl=0" --run "$dir/new" --samples
expect "udpm://239.255.76.67:20002?ttl=0" --run "$dir/old" --samples
expect "tcpq://10.0.0.5:20001" --run "$dir/tcp" --samples
expect "udpm://239.255.76.67:7667?ttl=0"  # no run: the default main URL
# Not a run folder: a clear error.
if bash "$spy" --print-url --run "$dir/none" 2> "$dir/err"; then fail "a folder without config.ini"; fi
grep -q "not a run folder" "$dir/err" || fail "unclear error: $(cat "$dir/err")"
echo "PASS: spy.sh's URLs from new, earlier-version and TCP run headers"
