# Sourced by the study scripts: run NAME ARGS... runs "$bin" ARGS once and adds its report to
# "$results" under NAME (docs/studies/results.py records the commit and machine).
run() {
  local name=$1; shift
  echo "== $name: $*"
  "$bin" "$@" --json "build/runs/$name.json"
  python3 docs/studies/results.py add "$results" "$name" "build/runs/$name.json"
}
