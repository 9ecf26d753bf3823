#!/usr/bin/env bash
# Writes one HTML page that overlays the evaluation curves of several runs (seeds or presets):
# runs of the same preset form a group, drawn as the mean across its runs with their min-max
# band, each run also as a thin line, against env steps and against wall time; then a table per
# group and per run (best and final scores, env steps and wall time at best, evaluations).
# The page is self-contained (inline SVG, nothing fetched): open it in any browser.
#
# Usage: scripts/compare.sh [--out FILE] [--build-dir DIR] RUN_DIR...
#   RUN_DIR          a run folder of scripts/launch.sh (config.ini and eval.jsonl)
#   --out FILE       the page to write (default compare.html in the current folder)
#   --build-dir DIR  where the binaries are built (default build)
# Example: scripts/compare.sh runs/cartpole-2026* runs/lunar_lander-2026* --out cmp.html
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)

usage() { awk 'NR > 1 && /^#/ { sub(/^# ?/, ""); print; next } NR > 1 { exit }' "$0"; }
die() { echo "compare: $*" >&2; exit 2; }

out=compare.html build_dir="$root/build"
runs=()
while [ $# -gt 0 ]; do
  case "$1" in
    -h|--help) usage; exit 0 ;;
    --out|--build-dir)
      [ $# -ge 2 ] || die "option $1 needs a value"
      [ "$1" = --out ] && out="$2" || build_dir="$2"
      shift ;;
    --) shift; runs+=("$@"); break ;;
    -*) die "unknown option '$1' (see --help)" ;;
    *) runs+=("$1") ;;
  esac
  shift
done
[ ${#runs[@]} -ge 1 ] || { usage >&2; exit 2; }
for run in "${runs[@]}"; do
  [ -d "$run" ] || die "$run: not a folder"
  [ -f "$run/config.ini" ] || die "$run: no config.ini (not a run folder of scripts/launch.sh)"
  [ -f "$run/eval.jsonl" ] || die "$run: no eval.jsonl (not a run folder, or no checkpoint scored)"
done
[ -d "$(dirname "$out")" ] || die "$(dirname "$out"): no such folder for --out"
tool="$build_dir/bin/compare"
[ -x "$tool" ] || die "$tool is missing: run scripts/setup.sh (or pass --build-dir)"
# A folder named like an option reaches the tool as ./NAME.
args=()
for run in "${runs[@]}"; do
  case "$run" in -*) args+=("./$run") ;; *) args+=("$run") ;; esac
done
case "$out" in -*) out="./$out" ;; esac
exec "$tool" --out "$out" "${args[@]}"
