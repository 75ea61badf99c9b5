# Sourced by the shell tests (after limn=$1 root=$2): what each of them
# needs alike, written once.
#   check NAME CONDITION...  runs CONDITION, counts it passed or failed (and names a failure)
#   finish                   prints the counts; its status is the test's: 0 when none failed
#   needs PROG WHY           exits 77 (skipped) when PROG is not installed; WHY says where it comes from
#   scratch NAME             a fresh folder /tmp/limn-NAME-XXXXXX in $tmp, removed on exit
#                            (under /tmp: POV-Ray's default I/O policy allows writing there)
#   fail MESSAGE             stops the test, failed
#   late_script FILE         writes a pipeline script whose sixth OnRender (frame 5 of a
#                            capture) fails: what a half-done sequence leaves
#   wait_until SECONDS CMD...  runs CMD every 0.1 s until it succeeds or SECONDS of wall time pass;
#                            fails when the time passes first (a deadline, not a count of tries:
#                            a loaded machine's slow tries do not shorten it)
passed=0 failed=0
check() {
  local name=$1; shift
  if "$@"; then passed=$((passed + 1)); else failed=$((failed + 1)); echo "FAIL: $name"; fi
}
finish() {
  echo "$passed passed, $failed failed"
  [ "$failed" -eq 0 ]
}
needs() {
  command -v "$1" >/dev/null || { echo "$1 not installed: skipped ($2)"; exit 77; }
}
scratch() {
  tmp=$(mktemp -d "/tmp/limn-$1-XXXXXX") || exit 1
  trap 'rm -rf "$tmp"' EXIT
}
fail() { echo "FAIL: $*"; exit 1; }
late_script() {
  cat >"$1" <<'LUA'
local gbuffer = require "gbuffer"
Techniques = { "gbuffer" }
local calls = 0
function OnRender(tech)
  calls = calls + 1
  if calls == 6 then error("frame 5 fails") end
  present(gbuffer.render(gbuffer.targets()).clr)
end
LUA
}
wait_until() {
  local end=$((SECONDS + $1)); shift
  until "$@"; do
    [ "$SECONDS" -ge "$end" ] && return 1
    sleep 0.1
  done
}
