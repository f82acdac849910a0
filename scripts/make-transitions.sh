#!/usr/bin/env bash
# Regenerates config/decoder/english-transitions.json, the decoder's class-to-class transition
# probabilities and minimum durations, from espeak-ng phonemisations of English text: the
# licence texts every Debian system ships (/usr/share/common-licenses) and the training
# sentences. Reproducible: the same espeak-ng and the same text give the same file.
#
#   scripts/make-transitions.sh [OUT.json]
#
# Transitions: bigram counts of common-set classes (runs of one class count once), add-one
# smoothed, as natural-log probabilities. Minimum durations: a fraction (MIN_FRACTION, default
# 0.4) of each class's median espeak-ng duration, in 10 ms hops: real speech is faster and more
# varied than espeak-ng, so the decoder must allow much shorter runs than the median.
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
lipsync="${LIPSYNC:-$here/build/cli/lipsync}"
out="${1:-$here/config/decoder/english-transitions.json}"
fraction="${MIN_FRACTION:-0.4}"
[ -x "$lipsync" ] || { echo "make-transitions.sh: $lipsync not built (run scripts/build.sh)" >&2; exit 1; }

work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
# One paragraph a line: licence paragraphs are separated by blank lines.
texts=(/usr/share/common-licenses/GPL-3 /usr/share/common-licenses/Apache-2.0
       /usr/share/common-licenses/LGPL-2.1 /usr/share/common-licenses/MPL-2.0)
{ cat "$here/config/corpus/train-sentences.txt" | grep -v '^#'
  for t in "${texts[@]}"; do
    [ -f "$t" ] && awk 'BEGIN{RS=""} {gsub(/[\n\t ]+/, " "); print}' "$t"
  done; } | grep -E '[A-Za-z]{3}' | cut -c1-600 >"$work/text.txt"

n=0
while IFS= read -r line; do
  n=$((n + 1))
  "$lipsync" say "$line" --schedule "$work/$n.lab" 2>/dev/null || true
done <"$work/text.txt"

python3 - "$work" "$out" "$fraction" "$here" <<'EOF'
import json, math, statistics, subprocess, sys
from pathlib import Path
work, out, fraction = Path(sys.argv[1]), Path(sys.argv[2]), float(sys.argv[3])
import tomllib
common = tomllib.loads((Path(sys.argv[4]) / "config/phonemes/common.toml").read_text())
classes = [c["name"] for c in common["class"]]
index = {c: i for i, c in enumerate(classes)}
n = len(classes)
counts = [[0] * n for _ in range(n)]
durations = [[] for _ in range(n)]
files = 0
for lab in sorted(work.glob("*.lab"), key=lambda p: int(p.stem)):
    runs = []
    for line in lab.read_text().splitlines():
        start, end, name = line.split("\t")[:3]
        if runs and runs[-1][0] == name:
            runs[-1][1] += float(end) - float(start)
        else:
            runs.append([name, float(end) - float(start)])
    runs = [["sil", 0.3]] + runs + [["sil", 0.3]]
    for (a, _), (b, _) in zip(runs, runs[1:]):
        counts[index[a]][index[b]] += 1
    for name, d in runs[1:-1]:
        durations[index[name]].append(d)
    files += 1
log_prob = []
for i in range(n):
    total = sum(counts[i][k] + 1 for k in range(n) if k != i)
    log_prob.append([0.0 if k == i else round(math.log((counts[i][k] + 1) / total), 4)
                     for k in range(n)])
min_frames = [max(1, int(fraction * statistics.median(d) / 0.01)) if d else 1 for d in durations]
version = subprocess.run(["espeak-ng", "--version"], capture_output=True, text=True).stdout.split()[3]
doc = {"format": "lipsyncd-transitions", "version": 1,
       "description": f"scripts/make-transitions.sh: espeak-ng {version} phonemisations of "
                      f"{files} paragraphs of English text; minimum {fraction} of the median duration",
       "classes": classes, "min_frames": min_frames, "log_prob": log_prob}
out.parent.mkdir(parents=True, exist_ok=True)
out.write_text(json.dumps(doc, indent=1) + "\n")
print(f"make-transitions.sh: {out} from {files} paragraphs; min frames "
      + " ".join(f"{c}={m}" for c, m in zip(classes, min_frames)), file=sys.stderr)
EOF
