#!/usr/bin/env python3
"""scripts/held-out-check.sh and train-templates.sh's --leave-out, with a stand-in for the
lipsync tool (no speech, no training): a speaker left out is trained without and scored on the
set trained without it, the held-out voices on the full set, and bad arguments are refused."""
import importlib.util
import json
import os
import subprocess
import tempfile
import unittest
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
CHECK = ROOT / "scripts" / "held-out-check.sh"
TRAIN = ROOT / "scripts" / "train-templates.sh"
TRAINING_SPEAKERS = ["asterisk-en-allison", "klettres-en-gb", "asterisk-it-carlo",
                     "asterisk-es-allison"]
# Speakers in the networks only (config/corpus/real-speakers.txt's `networks` split), read as
# the labeller reads the list.
_spec = importlib.util.spec_from_file_location("label_real_speech",
                                               ROOT / "scripts" / "label-real-speech.py")
_labeller = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(_labeller)
NETWORK_SPEAKERS = [speaker for speaker, split, _ in
                    _labeller.load_speakers(ROOT / "config/corpus/real-speakers.txt")
                    if split == "networks"]

# The stand-in: logs every call; `say` writes files, `train` a set, `eval` figures in which a
# speaker scored on the set trained without it reads 25 % and on any other set 75 %.
FAKE_LIPSYNC = r"""#!/usr/bin/env bash
echo "$*" >>"$FAKE_LOG"
command=$1; shift
case "$command" in
  say) while [ $# -gt 0 ]; do
         case "$1" in --wav) : >"$2"; shift ;; --schedule) echo "0 1 sil" >"$2"; shift ;; esac
         shift
       done ;;
  train) while [ $# -gt 0 ]; do [ "$1" = -o ] && echo '{"description": "stand-in"}' >"$2"; shift; done ;;
  eval) exec python3 -c '
import json, sys
from pathlib import Path
args = sys.argv[1:]
corpus, templates, out = (args[args.index(k) + 1] for k in ("--corpus", "--templates", "--json"))
speakers = {}
for d in sorted(Path(corpus).iterdir()):
    if d.is_dir():
        own = Path(templates).name == f"without-{d.name}.json"
        jaw = {"r": 0.5, "closures": 4, "closures_caught": 0.75, "false_closures": 0.1}
        speakers[d.name] = {"group_accuracy": 0.25 if own else 0.75, "jaw": {"audio": jaw}}
Path(out).write_text(json.dumps({"group_accuracy": 0.75, "speakers": speakers}))
' "$@" ;;
esac
"""


class HeldOutCheck(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.TemporaryDirectory()
        self.root = Path(self.dir.name)
        self.log = self.root / "calls.log"
        self.fake = self.root / "lipsync"
        self.fake.write_text(FAKE_LIPSYNC)
        self.fake.chmod(0o755)
        self.real = self.root / "real"
        for speaker in TRAINING_SPEAKERS:
            (self.real / "train" / speaker).mkdir(parents=True)
        for speaker in NETWORK_SPEAKERS:
            (self.real / "networks" / speaker).mkdir(parents=True)
        for voice in ("asterisk-ru-f", "fillets-cs-v"):
            (self.real / "tune" / voice).mkdir(parents=True)
        self.env = dict(os.environ, LIPSYNC=str(self.fake), FAKE_LOG=str(self.log),
                        REAL_SPEECH_DIR=str(self.real), CORPUS_DIR=str(self.root / "train"),
                        CORPUS_DEV_DIR=str(self.root / "dev"))

    def tearDown(self):
        self.dir.cleanup()

    def run_script(self, script, *args):
        return subprocess.run([str(script), *args], env=self.env, capture_output=True, text=True,
                              timeout=300)

    def test_each_speaker_left_out_is_trained_without_and_scored_on_that_set(self):
        work = self.root / "work"
        result = self.run_script(CHECK, "--no-fetch", "--work", str(work))
        self.assertEqual(result.returncode, 0, result.stderr)
        trainings = [c for c in self.log.read_text().splitlines()
                     if c.startswith("train ") and "--keep-templates" not in c]
        for speaker in ("klettres-en-gb", "asterisk-en-allison"):
            without = [c for c in trainings if f"without-{speaker}.json" in c]
            self.assertEqual(len(without), 1, trainings)
            self.assertNotIn(f"/train/{speaker} ", without[0] + " ")
            for other in set(TRAINING_SPEAKERS) - {speaker}:
                self.assertIn(f"/train/{other} ", without[0] + " ")
            lines = [l for l in result.stdout.splitlines() if l.strip().startswith(speaker + ",")]
            self.assertEqual(len(lines), 2, result.stdout)  # audio only and aligned
            for line in lines:
                self.assertIn("25.0 %", line)  # scored on the set trained without it
        full = [c for c in trainings if "all.json" in c]
        self.assertEqual(len(full), 1, trainings)
        for speaker in TRAINING_SPEAKERS:
            self.assertIn(f"/train/{speaker} ", full[0] + " ")
        # The networks-only speakers are labelled by the aligner and go into the networks of
        # every set, never into its templates.
        networks = [c for c in self.log.read_text().splitlines()
                    if c.startswith("train ") and "--keep-templates" in c and "all.json" in c]
        self.assertEqual(len(networks), 1)
        self.assertTrue(NETWORK_SPEAKERS)
        for speaker in NETWORK_SPEAKERS:
            self.assertIn(f"/aligned/{speaker} ", networks[0] + " ")
            self.assertNotIn(f"/{speaker} ", full[0] + " ")
        for voice in ("asterisk-ru-f", "fillets-cs-v"):
            lines = [l for l in result.stdout.splitlines() if l.strip().startswith(voice + ",")]
            self.assertEqual(len(lines), 2, result.stdout)
            for line in lines:
                self.assertIn("75.0 %", line)
        aligned = [c for c in self.log.read_text().splitlines()
                   if c.startswith("eval ") and "/tune" in c and "--align" in c]
        self.assertEqual(len(aligned), 1)
        # Each voice is read by the espeak-ng voice of its language.
        self.assertIn("--voice asterisk-ru-f=ru", aligned[0])
        self.assertIn("--voice fillets-cs-v=cs", aligned[0])
        self.assertIn("espeak-ng dev, full set: 75.0 %", result.stdout)
        self.assertFalse((ROOT / "config" / "templates" / "all.json").exists())

    def test_a_seed_reaches_every_training(self):
        out = self.root / "seeded.json"
        result = self.run_script(TRAIN, "--no-fetch", "--seed", "7", "-o", str(out))
        self.assertEqual(result.returncode, 0, result.stderr)
        trainings = [c for c in self.log.read_text().splitlines() if c.startswith("train ")]
        self.assertGreaterEqual(len(trainings), 2)  # the templates, then the networks
        for call in trainings:
            self.assertIn("--seed 7 ", call + " ")
        result = self.run_script(TRAIN, "--seed", "seven")
        self.assertEqual(result.returncode, 2)
        self.assertIn("usage: scripts/train-templates.sh", result.stderr)

    def test_missing_real_speech_is_named(self):
        self.env["REAL_SPEECH_DIR"] = str(self.root / "nowhere")
        result = self.run_script(CHECK, "--no-fetch", "--work", str(self.root / "work"))
        self.assertEqual(result.returncode, 1)
        self.assertIn(str(self.root / "nowhere" / "tune") + " missing", result.stderr)

    def test_bad_arguments_are_refused(self):
        result = self.run_script(CHECK, "--bogus")
        self.assertEqual(result.returncode, 2)
        self.assertIn("usage: scripts/held-out-check.sh", result.stderr)
        result = self.run_script(CHECK, "--help")
        self.assertEqual(result.returncode, 0)
        self.assertIn("--no-fetch", result.stdout)
        result = self.run_script(TRAIN, "--leave-out")
        self.assertEqual(result.returncode, 2)
        self.assertIn("usage: scripts/train-templates.sh", result.stderr)
        # A dev speaker is never in training: leaving it out means nothing, and says so.
        result = self.run_script(TRAIN, "--leave-out", "festvox-ru-nsh", "--no-fetch")
        self.assertEqual(result.returncode, 2)
        self.assertIn("--leave-out festvox-ru-nsh: not a training speaker", result.stderr)
        self.assertFalse(self.log.exists())  # refused before anything ran


if __name__ == "__main__":
    unittest.main()
