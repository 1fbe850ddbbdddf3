#!/usr/bin/env bash
# --json with file names that are not valid UTF-8 (issue 24): build and info
# must exit 0 and print the bad bytes as U+FFFD, not abort.
# Usage: check_non_utf8_names.sh LDC MESH
set -u
ldc=$1
mesh=$2
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
in="$dir/$(printf 'mesh\377.obj')"
world="$dir/$(printf 'world\376.ldc')"
cp "$mesh" "$in"
replacement=$(printf '\357\277\275')
out=$("$ldc" -q --json build "$in" --cells 16 -o "$world") || { echo "build exited $?"; exit 1; }
case "$out" in *"$replacement"*) ;; *) echo "build: no U+FFFD in the JSON"; exit 1 ;; esac
out=$("$ldc" -q --json info "$world") || { echo "info exited $?"; exit 1; }
case "$out" in *"$replacement"*) ;; *) echo "info: no U+FFFD in the stored source name"; exit 1 ;; esac
echo "ok"
