#!/usr/bin/env bash
# Runs one libFuzzer binary for a bounded time on a scratch copy of its
# committed seed corpus. Non-zero when the binary is absent (the test tree
# builds it, so that is a failed build), and with the crashing input's path
# when libFuzzer finds a crash.
set -u
bin=$1 corpus=$2 seconds=$3
if [ ! -x "$bin" ]; then
  echo "FAIL: $bin not built (deploy/test builds it in build/test with clang, -DSKY_FUZZ=ON)"
  exit 1
fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mkdir -p "$work/corpus" "$work/artifacts"
[ -d "$corpus" ] && cp -r "$corpus"/. "$work/corpus/" 2>/dev/null
"$bin" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -print_final_stats=1 \
  -artifact_prefix="$work/artifacts/" "$work/corpus" 2>&1 | tail -25
status=${PIPESTATUS[0]}
if [ "$status" -ne 0 ]; then
  mkdir -p "${FUZZ_ARTIFACTS:-/tmp/skyshell-fuzz-artifacts}"
  cp "$work"/artifacts/* "${FUZZ_ARTIFACTS:-/tmp/skyshell-fuzz-artifacts}/" 2>/dev/null
  echo "FAIL: $(basename "$bin") found a crash; input saved in ${FUZZ_ARTIFACTS:-/tmp/skyshell-fuzz-artifacts}/"
  exit 1
fi
echo "$(basename "$bin"): no crash in $seconds s"
