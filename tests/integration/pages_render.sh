#!/usr/bin/env bash
# The pages a person reads render in a real browser, and a run records its LCM traffic:
#   - two short CartPole runs (seeds 1 and 2), the first with --record and a cap of 8 MB (its
#     main port carries some MB a second, so the recording rotates);
#   - Debian's chromium, headless, renders the first run's report/index.html and the compare page
#     of both runs (scripts/compare.sh): a screenshot that is a PNG and not blank, every image of
#     the page loaded, no failed load and no console message;
#   - the recording (RUN/lcm-log/) is not empty, rotated within its cap, and plays back:
#     lcm-logplayer plays it into a monitor listening with the run's id on a fresh port, which
#     decodes the run's evaluations up to one as good as its last.
# RL_KEEP=1 keeps the scratch folder (screenshots: */*.png there).
source "$(dirname "$0")/lib.sh"
isolate "$@"
scratch
here=$(cd "$(dirname "$0")" && pwd)
command -v chromium >/dev/null || fail "chromium is missing (scripts/setup.sh installs it)"
command -v lcm-logplayer >/dev/null || fail "lcm-logplayer is missing (liblcm-bin: scripts/setup.sh)"

# Two runs, one after the other (each some seconds: CartPole solves fast).
set +e
launch cartpole --out "$dir/seed1" --actors 2 --seed 1 --time-budget 120 --record --record-mb 8 \
  > "$dir/launch1.log" 2>&1
status1=$?
launch cartpole --out "$dir/seed2" --actors 2 --seed 2 --time-budget 120 > "$dir/launch2.log" 2>&1
status2=$?
set -e
tail -n 4 "$dir/launch1.log" "$dir/launch2.log"
[ "$status1" -le 1 ] || fail "the first launch exited with $status1"
[ "$status2" -le 1 ] || fail "the second launch exited with $status2"
for run in seed1 seed2; do
  [ -s "$dir/$run/eval.jsonl" ] || fail "$run: no evaluation"
done
grep -q '^recorder ' "$dir/seed1/pids" || fail "the recorder is not in the pids file"
[ ! -e "$dir/seed2/lcm-log" ] || fail "a run without --record has a recording"

# ---- The recording ----
# The files oldest first: main.lcmlog.7 ... main.lcmlog.0.
logs=()
for name in $(cd "$dir/seed1/lcm-log" && ls main.lcmlog.* 2>/dev/null | sort -t. -k3 -rn); do
  [ ! -s "$dir/seed1/lcm-log/$name" ] || logs+=("$dir/seed1/lcm-log/$name")
done
[ ${#logs[@]} -gt 0 ] || fail "no recording in seed1/lcm-log"
recorder_pid=$(awk '$1 == "recorder" {print $2}' "$dir/seed1/pids")
! kill -0 "$recorder_pid" 2>/dev/null || fail "the recorder outlived its run"
grep -q 'Logger exiting' "$dir/seed1/logs/recorder.log" || fail "the recorder did not stop cleanly"
# An LCM log event starts with the sync word 0xEDA1DA01.
[ "$(head -c 4 "${logs[0]}" | od -An -tx1 | tr -d ' ')" = "eda1da01" ] ||
  fail "the recording does not start with an LCM event"
bytes=$(cat "${logs[@]}" | wc -c)
echo "recording: $bytes bytes in ${#logs[@]} files"
# 8 files of 1 MB at most (each closed once it exceeds 1 MB: one event more).
[ "$(ls "$dir/seed1/lcm-log" | wc -l)" -le 8 ] || fail "more than 8 files: $(ls "$dir/seed1/lcm-log")"
[ ${#logs[@]} -ge 2 ] || fail "the recording did not rotate ($bytes bytes in one file)"
[ "$bytes" -le $((8 * 1024 * 1024 + 8 * 65536)) ] || fail "the recording exceeds its cap: $bytes bytes"
# Play it (the evaluations and stats, 10x as fast) into a monitor of the run's id on its own port:
# the monitor ends with "goal reached" once it decodes an evaluation as good as the run's last
# (the newest file holds the last; the oldest files may have gone).
run_id=$(run_setting "$dir/seed1" run-id)
last=$(tail -n 1 "$dir/seed1/eval.jsonl" | grep -Eo '"mean": *[-0-9.e+]+' | grep -Eo '[-0-9.e+]+$')
port=7790
url="udpm://239.255.76.67:$port?ttl=0&recv_buf_size=4194304"
bulk_url="udpm://239.255.76.67:$((port + 1))?ttl=0&recv_buf_size=4194304"
samples_url="udpm://239.255.76.67:$((port + 2))?ttl=0&recv_buf_size=4194304"
"$bin/monitor" --run-id "$run_id" --lcm-url "$url" --lcm-bulk-url "$bulk_url" \
  --lcm-samples-url "$samples_url" --goal "$last" \
  --time-budget 60 --stale-seconds 60 > "$dir/replayed.log" 2>&1 &
monitor_pid=$!
wait_line "$dir/replayed.log" "monitor: ready" 10
for log in "${logs[@]}"; do
  lcm-logplayer --speed=10 --regexp='RL_(EVAL|STATS_.*)' --lcm-url="$url" "$log" \
    > "$dir/logplayer.log" 2>&1 || fail "lcm-logplayer failed on $log"
done
timeout 30 tail --pid="$monitor_pid" -f /dev/null || fail "the monitor did not end"
wait "$monitor_pid" || { cat "$dir/replayed.log"; fail "the replayed recording did not reach $last"; }
grep -q -- '-- goal reached' "$dir/replayed.log" || fail "no evaluation decoded from the recording"
evaluations=$(grep -c '^evaluation: ' "$dir/replayed.log")
echo "replayed: $evaluations evaluations decoded, up to one of $last or more"

# ---- The compare page ----
"$root/scripts/compare.sh" --build-dir "$build_dir" --out "$dir/compare.html" \
  "$dir/seed1" "$dir/seed2" | tee "$dir/compare.log"
grep -q 'wrote .*compare.html: 2 runs of 1 preset' "$dir/compare.log" || fail "compare.sh said no"
for run in seed1 seed2; do
  grep -q ">$run<" "$dir/compare.html" || fail "the compare page lacks $run"
done
# A folder that is not a run: one clear line, exit 2.
mkdir -p "$dir/empty"
set +e
"$root/scripts/compare.sh" --build-dir "$build_dir" "$dir/empty" > "$dir/refused.log" 2>&1
refused=$?
set -e
if [ "$refused" -ne 2 ] || [ "$(wc -l < "$dir/refused.log")" -ne 1 ] ||
   ! grep -q "^compare: .*empty: no config.ini" "$dir/refused.log"; then
  fail "compare.sh on a folder that is no run: exit $refused, said $(cat "$dir/refused.log")"
fi

# ---- The browser ----
chrome=(chromium --headless --no-sandbox --disable-gpu --hide-scrollbars --no-first-run
        --disable-extensions --enable-logging=stderr --v=0)
# Checks the PNG file $1: its signature, and decoded by chromium: $2 x $3 pixels, not blank.
expect_png() {  # expect_png FILE WIDTH HEIGHT
  local stats
  [ "$(head -c 8 "$1" | od -An -tx1 | tr -d ' ')" = "89504e470d0a1a0a" ] || fail "$1 is not a PNG"
  cp "$here/png_stats.html" "$(dirname "$1")/png_stats.html"
  stats=$(timeout 60 "${chrome[@]}" --allow-file-access-from-files --virtual-time-budget=5000 \
            --dump-dom "file://$(dirname "$1")/png_stats.html#$(basename "$1")" 2>/dev/null |
          grep -o 'data-png="[^"]*"' || true)
  echo "$(basename "$1"): $stats"
  awk -v s="$stats" -v w="$2" -v h="$3" 'BEGIN {
      n = split(s, kv, /[ "=]+/); for (i = 1; i < n; i++) v[kv[i]] = kv[i + 1]
      exit !(v["width"] == w && v["height"] == h && v["colors"] >= 32 && v["other"] >= 0.05) }' ||
    fail "$1 is blank or not $2x$3 ($stats)"
}
# Renders the page $1: a screenshot $2 (W x H), no console message from the page; then a copy
# with the probe script: every image loaded, no failed load, no console error or warning; prints
# the probe's counts (in probe_images and probe_svgs).
render() {  # render PAGE SHOT WIDTH HEIGHT
  local page=$1 shot=$2 w=$3 h=$4 copy probe
  timeout 60 "${chrome[@]}" --window-size="$w,$h" --screenshot="$shot" "file://$page" \
    > "$shot.log" 2>&1 || fail "chromium could not render $page (log: $shot.log)"
  [ -s "$shot" ] || fail "no screenshot of $page"
  # Console messages of the page (the browser's own pages, chrome://, log some of their own).
  ! grep ':CONSOLE' "$shot.log" | grep -q 'source: file://' ||
    fail "console messages on $page: $(grep ':CONSOLE' "$shot.log" | grep 'source: file://')"
  expect_png "$shot" "$w" "$h"
  copy="$(dirname "$page")/probe-$(basename "$page")"
  cp "$here/page_probe.js" "$(dirname "$page")/page_probe.js"
  sed 's|<head>|<head><script src="page_probe.js"></script>|' "$page" > "$copy"
  probe=$(timeout 60 "${chrome[@]}" --window-size="$w,$h" --virtual-time-budget=10000 \
            --dump-dom "file://$copy" 2>/dev/null | tr '\n' '|' |
          grep -o 'data-rl-probe="[^"]*"' || true)
  [ -n "$probe" ] || fail "the probe of $page did not report (did the page load?)"
  echo "$(basename "$page"): $probe"
  echo "$probe" | grep -q ' broken=0 ' || fail "images of $page did not load: $probe"
  echo "$probe" | grep -q ' errors=0"' || fail "errors on $page: $probe"
  probe_images=$(echo "$probe" | sed -n 's/.*images=\([0-9]*\).*/\1/p')
  probe_svgs=$(echo "$probe" | sed -n 's/.* svgs=\([0-9]*\).*/\1/p')
}
render "$dir/seed1/report/index.html" "$dir/seed1/report.png" 1280 2400
[ "$probe_images" -ge 3 ] || fail "the report shows $probe_images images (curves expected)"
render "$dir/compare.html" "$dir/compare.png" 1280 1800
[ "$probe_svgs" -eq 2 ] || fail "the compare page has $probe_svgs plots, not 2"
[ -z "${RL_KEEP:-}" ] || echo "screenshots: $dir/seed1/report.png $dir/compare.png"
expect_no_restarts "$dir/seed1"
expect_no_restarts "$dir/seed2"
echo "PASS: report and compare page render (screenshots, images, no console message);" \
  "the recording plays back ($evaluations evaluations)"
