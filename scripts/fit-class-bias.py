#!/usr/bin/env python3
"""Fit a template set's class bias (class_bias_db) on real voices held out of its training.

The front end is trained mostly on espeak-ng, whose classes come in other proportions and other
shapes than a person's: on real voices it hears too many bilabials, /r/ and /w/ and too few
vowels. A dB added to each class's distance corrects that, as a prior would. This script
chooses those dB by coordinate search: each class in turn is moved by a step either way and the
move kept when the score over the voices rises, until no move helps; then the step is halved.

The score is what a puppet shows, summed over the speakers of every corpus (`lipsync eval`,
audio only, per speaker, in percent): visual groups + 50 × jaw r + 0.5 × (bilabial closures
caught − false closures). A hundredth of jaw r weighs half a point of visual groups; a closure
caught and a false closure weigh the same. With --live-too each corpus is also scored through
the service's live path (`eval --live`) and both scores are added: the live mouth has no dips of
the jaw to close it and leans on the bilabials heard, so a bias fitted on files alone can cost it
closures.

    scripts/fit-class-bias.py --set config/templates/default.json \\
        --corpus build/real-speech/tune --write

Use voices the set was not trained on (the `tune` split of config/corpus/real-speakers.txt), and
never the dev speakers or the sources speech-data.md reserves. `--corpus DIR=SET` scores DIR on
another set (a training speaker on a set trained without it). Deterministic: the same set,
corpora and binary give the same bias. Prints each move kept; --write puts the result into SET
(class_bias_db), leaving the rest of the file as it is.
"""
import argparse
import json
import os
import re
import subprocess
import sys
import tempfile
import tomllib
from concurrent.futures import ThreadPoolExecutor

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def common_classes():
    """The classes a set's bias may name, in the common set's order (config/phonemes)."""
    with open(os.path.join(ROOT, "config", "phonemes", "common.toml"), "rb") as f:
        return [c["name"] for c in tomllib.load(f)["class"]]


def parse_args(argv):
    p = argparse.ArgumentParser(description=__doc__,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--set", required=True, help="template set (JSON) whose bias is fitted")
    p.add_argument("--corpus", action="append", required=True,
                   help="DIR (scored on --set) or DIR=SET: speakers in subfolders; repeatable")
    p.add_argument("--lipsync", default=os.environ.get("LIPSYNC", os.path.join(ROOT, "build/cli/lipsync")),
                   help="the tool (default: $LIPSYNC, else build/cli/lipsync)")
    p.add_argument("--steps", default="0.3,0.15", help="dB steps, largest first (default 0.3,0.15)")
    p.add_argument("--min-gain", type=float, default=1.0,
                   help="score a move must add to be kept (default 1: about a point of visual "
                        "groups; smaller moves fit the voices' quirks)")
    p.add_argument("--jobs", type=int, default=2, help="evaluations run at once (default 2)")
    p.add_argument("--start", default="", help="starting bias, CLASS=DB,... (default: none)")
    p.add_argument("--live-too", action="store_true",
                   help="also score each corpus through the live path (eval --live) and add it")
    p.add_argument("--write", action="store_true", help="write the bias into --set")
    p.add_argument("eval_options", nargs="*", help="after --: more `lipsync eval` options")
    return p.parse_args(argv)


def evaluate(args, bias):
    """Per speaker over every corpus: (visual groups, jaw r, closures caught, false), percent."""
    rows = []
    paths = [[], ["--live"]] if args.live_too else [[]]
    for item, path in ((i, p) for i in args.corpus for p in paths):
        corpus, _, tset = item.partition("=")
        with tempfile.NamedTemporaryFile(suffix=".json") as out:
            cmd = [args.lipsync, "eval", "--corpus", corpus, "--templates", tset or args.set,
                   "--no-per-file", "--json", out.name, "--no-class-bias", *path,
                   *args.eval_options]
            for name, db in sorted(bias.items()):
                if db:
                    cmd += ["--class-bias", f"{name}={db:g}"]
            done = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
            if done.returncode != 0:
                sys.exit(f"fit-class-bias: {' '.join(cmd)} failed:\n{done.stderr}")
            figures = json.load(open(out.name))
        for name, s in sorted(figures["speakers"].items()):
            a = s["jaw"]["audio"]
            rows.append((name, 100 * s["group_accuracy"], a["r"], 100 * a["closures_caught"],
                         100 * a["false_closures"]))
    return rows


def score(rows):
    g = sum(r[1] for r in rows)
    j = sum(r[2] for r in rows)
    caught = sum(r[3] for r in rows)
    false = sum(r[4] for r in rows)
    return g + 50 * j + 0.5 * (caught - false), f"groups {g:.1f} jaw {j:.2f} caught {caught:.1f} false {false:.1f}"


def fit(args):
    bias = {}
    for item in filter(None, args.start.split(",")):
        name, _, db = item.partition("=")
        bias[name] = float(db)
    best, figures = score(evaluate(args, bias))
    print(f"start: score {best:.2f} ({figures})", flush=True)
    with ThreadPoolExecutor(max_workers=args.jobs) as pool:
        for step in (float(s) for s in args.steps.split(",")):
            moved = True
            while moved:
                moved = False
                # Both directions of one class at once; the first class whose move helps is
                # kept, then the sweep starts again from the first class.
                for name in common_classes():
                    trials = []
                    for sign in (1, -1):
                        b = dict(bias)
                        b[name] = round(b.get(name, 0) + sign * step, 3)
                        trials.append(b)
                    results = list(pool.map(lambda b: (score(evaluate(args, b)), b), trials))
                    (s, f), b = max(results, key=lambda r: r[0][0])
                    if s > best + args.min_gain:
                        best, figures, bias, moved = s, f, b, True
                        print(f"step {step}: {name} {b[name]:+.3f} dB: score {best:.2f} ({f})",
                              flush=True)
                        break
    bias = {k: v for k, v in sorted(bias.items()) if v}
    print(f"fitted: score {best:.2f} ({figures})")
    print(json.dumps(bias))
    return bias


def write(path, bias):
    """Replaces (or adds) the set's class_bias_db, leaving every other line as it is. A set
    another tool wrote (not laid out as `lipsync` writes one) is written again whole, in
    `lipsync`'s layout, rather than losing a fit that took minutes."""
    text = open(path).read()
    whole = json.loads(text)  # a broken set is not ours to rewrite
    block = ' "class_bias_db": ' + json.dumps(bias, indent=1).replace("\n", "\n ") + ",\n"
    text, n = re.subn(r' "class_bias_db": \{[^}]*\},\n', lambda _: block, text)
    if n == 0:
        at = text.find('\n "class')  # before class_network / classes, as lipsync writes it
        if at < 0:
            whole["class_bias_db"] = bias
            text = json.dumps(dict(sorted(whole.items())), indent=1) + "\n"
            print(f"fit-class-bias: {path} is not laid out as lipsync writes a set: written "
                  "again whole", file=sys.stderr)
        else:
            text = text[:at + 1] + block + text[at + 1:]
    json.loads(text)
    open(path, "w").write(text)
    print(f"fit-class-bias: wrote class_bias_db into {path}")


def main(argv):
    args = parse_args(argv)
    if not os.access(args.lipsync, os.X_OK):
        sys.exit(f"fit-class-bias: {args.lipsync}: not built (scripts/build.sh)")
    bias = fit(args)
    if args.write:
        write(args.set, bias)


if __name__ == "__main__":
    main(sys.argv[1:])
