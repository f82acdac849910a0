#!/bin/sh
# Whole-program before/after check for front-end optimisations: runs two builds of `lipsync`
# over the same audio files and compares, byte for byte, the schedules (fixed-lag and offline
# decoding, and frame by frame) and the per-frame CSV (levels, noise floor, error, classes,
# distances). An optimisation that is meant not to change results must report no difference.
#
#   bench/compare-analysis.sh OLD_LIPSYNC NEW_LIPSYNC FILE.wav...
#   e.g. bench/compare-analysis.sh /tmp/lipsync-main build/cli/lipsync /work/data/corpus/dev/*/*.wav
set -eu
if [ $# -lt 3 ]; then
    echo "usage: $0 OLD_LIPSYNC NEW_LIPSYNC FILE.wav..." >&2
    exit 2
fi
old=$1
new=$2
shift 2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
files=0
differing=0
for f in "$@"; do
    files=$((files + 1))
    for mode in lag offline frames; do
        case $mode in
            lag) args="" ;;
            offline) args="--offline" ;;
            frames) args="--no-decoder" ;;
        esac
        for which in old new; do
            if [ $which = old ]; then bin=$old; else bin=$new; fi
            # shellcheck disable=SC2086
            "$bin" analyze "$f" -q $args -s "$work/$which.tsv" --frames "$work/$which.csv"
        done
        if ! cmp -s "$work/old.tsv" "$work/new.tsv" || ! cmp -s "$work/old.csv" "$work/new.csv"; then
            echo "DIFFERENT ($mode): $f"
            diff "$work/old.tsv" "$work/new.tsv" | head -5 || true
            diff "$work/old.csv" "$work/new.csv" | head -5 || true
            differing=$((differing + 1))
        fi
    done
done
echo "$files files, 3 modes each: $differing runs differ"
[ "$differing" -eq 0 ]
