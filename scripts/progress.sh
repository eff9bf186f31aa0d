# Sourced by demo.sh and test.sh: short progress for set-up and build instead
# of minutes of silence (or of compiler lines). The full build log goes to
# build.log; on failure its tail is printed.

step() { echo "== $*"; }

# build_quietly [scripts/build.sh args...]: "build: 40 % (123 s)" on one
# line rewritten in place on a terminal, one line per 10 % otherwise.
build_quietly() {
  local log=build/build.log start=$SECONDS last=-10 pct line
  mkdir -p build
  : >"$log"
  set +e
  scripts/build.sh "$@" 2>&1 | while IFS= read -r line; do
    printf '%s\n' "$line" >>"$log"
    case "$line" in
      \[*%\]*)
        pct=${line#[}; pct=${pct%%%*}; pct=${pct// /}
        if [ -t 1 ]; then
          printf '\r   build: %3s %% (%d s)' "$pct" $((SECONDS - start))
        elif [ "$pct" -ge $((last + 10)) ]; then
          printf '   build: %3s %% (%d s)\n' "$pct" $((SECONDS - start))
          last=$pct
        fi ;;
    esac
  done
  local rc=${PIPESTATUS[0]}
  set -e
  [ -t 1 ] && printf '\n'
  if [ "$rc" -ne 0 ]; then
    echo "build failed (exit $rc); last lines of $log:"
    tail -n 40 "$log"
    return "$rc"
  fi
  echo "   build: done in $((SECONDS - start)) s (log: $log)"
  report_warnings "$log"
}

# report_warnings LOG: the count of compiler warnings in a build log (of the
# files compiled in that build: all of them on a clean checkout, as in CI),
# and the warnings themselves when there are any.
report_warnings() {
  local n
  n=$(grep -c 'warning:' "$1" || true)
  echo "   compiler warnings: $n"
  [ "$n" -eq 0 ] || grep -A3 'warning:' "$1" | head -n 200
}
