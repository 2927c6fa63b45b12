#!/bin/sh
# usage: systemd_unit_test.sh PREFIX
# Validates the installed hposed.service with `systemd-analyze verify` (syntax, known keys,
# an executable ExecStart). Exits 77 (skipped) when systemd-analyze is missing or cannot run.
unit="$1/lib/systemd/system/hposed.service"
if ! command -v systemd-analyze > /dev/null 2>&1; then
  echo "SKIP: systemd-analyze not found (Debian package systemd)"
  exit 77
fi
if ! systemd-analyze --version > /dev/null 2>&1; then
  echo "SKIP: systemd-analyze cannot run here"
  exit 77
fi
[ -f "$unit" ] || { echo "FAIL: $unit not installed"; exit 1; }
# Unknown keys and bad values are only warnings for systemd: any message fails the test.
messages=$(systemd-analyze verify "$unit" 2>&1)
status=$?
if [ "$status" -ne 0 ] || [ -n "$messages" ]; then
  echo "FAIL: systemd-analyze verify $unit (status $status):"
  echo "$messages"
  exit 1
fi
echo "OK: systemd-analyze verify $unit"
