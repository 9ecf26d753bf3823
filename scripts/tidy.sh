#!/usr/bin/env bash
# Runs clang-tidy (clang-tidy-14, the checks of .clang-tidy) over the project's sources, with the
# compile database of a clang build. Any finding fails (.clang-tidy makes every check an error).
#
#   scripts/tidy.sh [options] --all          every source file of the build (about 10 s of CPU
#                                            each: minutes on two cores)
#   scripts/tidy.sh [options] --changed      the sources the last commit changed; when the history
#                                            ends with merges, those of all these merges (what CI
#                                            checks)
#   scripts/tidy.sh [options] --since REV    the sources changed since REV (e.g. main)
#   scripts/tidy.sh [options] FILE...        these files
#
# A changed header is checked through the source files of the build that include it.
# Options:
#   --build-dir DIR   the build whose compile_commands.json is read (default build-asan; it must
#                     be built, since sources include the generated message headers)
#   --jobs N          files checked side by side (default: the number of CPUs)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"

build_dir=build-asan jobs=$(nproc) mode="" since="" files=()
usage() { awk 'NR > 1 && /^#/ { sub(/^# ?/, ""); print; next } NR > 1 { exit }' "$0"; }
while [ $# -gt 0 ]; do
  case "$1" in
    --all) mode=all ;;
    --changed) mode=changed ;;
    --since) mode=since; since="$2"; shift ;;
    --build-dir) build_dir="$2"; shift ;;
    --jobs) jobs="$2"; shift ;;
    -h|--help) usage; exit 0 ;;
    -*) echo "tidy.sh: unknown option '$1' (see --help)" >&2; exit 2 ;;
    *) mode=files; files+=("$1") ;;
  esac
  shift
done
[ -n "$mode" ] || { echo "tidy.sh: say what to check: --all, --changed, --since REV or files" >&2; exit 2; }
db="$build_dir/compile_commands.json"
[ -f "$db" ] || { echo "tidy.sh: no $db (cmake --preset asan && cmake --build --preset asan)" >&2; exit 2; }
command -v clang-tidy-14 >/dev/null || { echo "tidy.sh: clang-tidy-14 is missing (scripts/setup.sh)" >&2; exit 2; }

# The project's sources in the database, relative to the root.
mapfile -t known < <(sed -n 's/^ *"file": "\(.*\)",\{0,1\}$/\1/p' "$db" | sed "s|^$root/||" |
  grep -v '^/' | grep -v '^build' | sort -u)
# The files a change touched: sources as they are, headers through the sources including them.
changed_sources() {
  local f
  while IFS= read -r f; do
    case "$f" in
      *.cc) printf '%s\n' "$f" ;;
      *.h) printf '%s\n' "${known[@]}" | xargs -r grep -l -F "#include \"$f\"" 2>/dev/null || true ;;
    esac
  done
}
case "$mode" in
  all) selected=("${known[@]}") ;;
  files) selected=("${files[@]}") ;;
  *)
    if [ "$mode" = changed ]; then
      # Back along the first parents while the commits are merges: the first other one is the base.
      since=HEAD
      while git rev-parse -q --verify "$since^2" >/dev/null; do since="$since^1"; done
      since="$since^1"
      git rev-parse -q --verify "$since" >/dev/null || since=$(git hash-object -t tree /dev/null)
    fi
    mapfile -t changed < <(git diff --name-only --diff-filter=AMR "$since" HEAD -- '*.cc' '*.h' |
      changed_sources | sort -u)
    # Only what the build compiles (a deleted or excluded file has nothing to check).
    selected=()
    for f in ${changed[@]+"${changed[@]}"}; do
      printf '%s\n' "${known[@]}" | grep -qxF "$f" && selected+=("$f")
    done
    ;;
esac
if [ ${#selected[@]} -eq 0 ]; then
  echo "tidy: no source file to check ($mode)"
  exit 0
fi

out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
start=$SECONDS
echo "tidy: checking ${#selected[@]} files ($mode), $jobs at a time"
# One output file per source; a file whose check failed keeps a .failed marker.
printf '%s\n' "${selected[@]}" | xargs -P "$jobs" -I{} sh -c '
  log="$1/$(echo "$2" | tr / _)"
  clang-tidy-14 -p "$3" --quiet "$2" >"$log" 2>&1 || touch "$log.failed"' sh "$out" {} "$build_dir"
failed=0
for f in "${selected[@]}"; do
  log="$out/$(echo "$f" | tr / _)"
  if [ -f "$log.failed" ]; then
    failed=$((failed + 1))
    grep -v -E '^[0-9]+ warnings? (and [0-9]+ errors? )?generated\.$' "$log" || true
  fi
done
echo "tidy: ${#selected[@]} files in $((SECONDS - start)) s, $failed with findings"
[ "$failed" -eq 0 ]
