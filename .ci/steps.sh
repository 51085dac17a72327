# Timed steps for .ci/run (sourced, not run). `step NAME` starts a step (ending the one before);
# `steps_done` ends the last. On exit, successful or not, a table of every step's wall time and
# the total is printed, and the same is written as JSON to $CI_TIMES (default
# target/ci-times.json). A step that fails is the last row, marked FAILED with its exit status.
#
# The steps' own commands run in the script's shell, so `set -e` keeps its meaning: the first
# failing command ends the run, and the EXIT trap names the step it belonged to.

CI_TIMES=${CI_TIMES:-${CARGO_TARGET_DIR:-target}/ci-times.json}
ci_names=()
ci_secs=()
ci_states=()
ci_current=""
ci_step_t0=0
ci_t0=$(date +%s.%N)

ci_now() { date +%s.%N; }
ci_elapsed() { awk -v a="$1" -v b="$(ci_now)" 'BEGIN { printf "%.1f", b - a }'; }

# Ends the current step (if any) with state $1.
ci_close() {
  if [ -n "$ci_current" ]; then
    ci_names+=("$ci_current")
    ci_secs+=("$(ci_elapsed "$ci_step_t0")")
    ci_states+=("$1")
    ci_current=""
  fi
  local i
  for ((i = 0; i < ${#ci_pending[@]}; i += 3)); do
    ci_names+=("${ci_pending[$i]}")
    ci_secs+=("${ci_pending[$((i + 1))]}")
    ci_states+=("${ci_pending[$((i + 2))]}")
  done
  ci_pending=()
}

step() {
  ci_close ok
  ci_current=$1
  ci_step_t0=$(ci_now)
  echo
  echo "== [$(date -u +%H:%M:%S)] $1"
}

steps_done() { ci_close ok; }

# Adds a row for work that ran in the background beside the current step (its own wall time,
# measured by whoever ran it), shown after that step's row: `step_row NAME SECONDS STATE`.
ci_pending=()
step_row() { ci_pending+=("$1" "$2" "$3"); }

# JSON string escaping for the step names (quotes and backslashes; names hold nothing else).
ci_json_str() { local s=${1//\\/\\\\}; printf '"%s"' "${s//\"/\\\"}"; }

ci_report() {
  local rc=$?
  ci_close "FAILED (exit $rc)"
  local total
  total=$(ci_elapsed "$ci_t0")
  echo
  echo "== step times (wall clock)"
  printf '| %-66s | %9s | %s\n' "step" "seconds" "state"
  printf '|%s|%s|%s\n' "--------------------------------------------------------------------" "-----------" "------"
  local i
  for i in "${!ci_names[@]}"; do
    printf '| %-66s | %9s | %s\n' "${ci_names[$i]}" "${ci_secs[$i]}" "${ci_states[$i]}"
  done
  printf '| %-66s | %9s | %s\n' "total" "$total" "$([ "$rc" = 0 ] && echo ok || echo "FAILED (exit $rc)")"
  mkdir -p "$(dirname "$CI_TIMES")"
  {
    printf '{\n  "total_s": %s,\n  "exit": %s,\n  "steps": [\n' "$total" "$rc"
    for i in "${!ci_names[@]}"; do
      printf '    {"name": %s, "seconds": %s, "state": %s}' "$(ci_json_str "${ci_names[$i]}")" \
        "${ci_secs[$i]}" "$(ci_json_str "${ci_states[$i]}")"
      [ "$i" -lt $((${#ci_names[@]} - 1)) ] && printf ','
      printf '\n'
    done
    printf '  ]\n}\n'
  } >"$CI_TIMES"
  echo "(also in $CI_TIMES)"
  return "$rc"
}

trap ci_report EXIT
