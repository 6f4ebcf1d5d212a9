#!/usr/bin/env bash
# Run a command (the test suite) while the image check (scripts/image/check.sh) runs beside it,
# so that `make test` pays for the longer of the two rather than their sum: the check spends
# most of its minutes waiting on downloads (Debian packages, about 1.8 GB of wheels), the suite
# on the CPU. The check's output goes to .image-check.log and is shown when both are done;
# the exit status is the command's, or 1 when the check failed or ran past its time.
#
#   bash scripts/image/alongside.sh COMMAND [ARG...]
#   MOCAPQA_IMAGE_CHECK_TIMEOUT   seconds the check may take (default 1200)
set -uo pipefail

ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
LOG="$ROOT/.image-check.log"
LIMIT=${MOCAPQA_IMAGE_CHECK_TIMEOUT:-1200}

timeout --signal=TERM --kill-after=60 "$LIMIT" bash "$ROOT/scripts/image/check.sh" >"$LOG" 2>&1 &
check=$!
"$@"
suite=$?
wait "$check"
image=$?
printf '\n== image check (scripts/image/check.sh, full output in %s) ==\n' "$LOG"
grep -E '^image-check: (\[|total|FAILED|WARNING)' "$LOG" || tail -n 40 "$LOG"
if [ "$image" = 124 ]; then
  printf 'image check: ran past %s s and was stopped\n' "$LIMIT"
elif [ "$image" != 0 ]; then
  printf 'image check: FAILED (exit %s); the last lines:\n' "$image"
  tail -n 40 "$LOG"
fi
[ "$suite" = 0 ] || exit "$suite"
[ "$image" = 0 ] || exit 1
