#!/usr/bin/env python3
"""scripts/fit-class-bias.py with a stand-in for `lipsync eval` whose score has a known best
bias: the search finds it, and --write puts it into the set without touching the rest."""
import json
import os
import subprocess
import sys
import tempfile
import unittest
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
FIT = ROOT / "scripts" / "fit-class-bias.py"

# Visual groups peak at ah −0.6 dB and w +0.3 dB; closures and jaw do not move, but through the
# live path (--live) the closures caught peak at bmp −0.3 dB. Every call must start from no bias
# (--no-class-bias) and say the biases it tries.
FAKE_LIPSYNC = r"""#!/usr/bin/env python3
import json, sys
args = sys.argv[1:]
assert args[0] == "eval" and "--no-class-bias" in args, args
bias = {}
for i, a in enumerate(args):
    if a == "--class-bias":
        name, db = args[i + 1].split("=")
        bias[name] = float(db)
g = 0.5 - 0.3 * (bias.get("ah", 0) + 0.6) ** 2 - 0.3 * (bias.get("w", 0) - 0.3) ** 2
caught = 0.9 - (0.5 * (bias.get("bmp", 0) + 0.3) ** 2 if "--live" in args else 0)
jaw = {"r": 0.7, "closures": 10, "closures_caught": caught, "false_closures": 0.05}
out = args[args.index("--json") + 1]
json.dump({"speakers": {"voice-a": {"group_accuracy": g, "jaw": {"audio": jaw}}}}, open(out, "w"))
"""

SET = """{
 "analysis": {
  "bins": 32
 },
 "bin_weights": [
  0.17311000000000001
 ],
 "classes": []
}
"""


class FitClassBias(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.TemporaryDirectory()
        self.root = Path(self.dir.name)
        self.fake = self.root / "lipsync"
        self.fake.write_text(FAKE_LIPSYNC.replace("/usr/bin/env python3", sys.executable, 1))
        self.fake.chmod(0o755)
        self.set = self.root / "set.json"
        self.set.write_text(SET)
        (self.root / "tune").mkdir()

    def tearDown(self):
        self.dir.cleanup()

    def fit(self, *extra):
        return subprocess.run([sys.executable, str(FIT), "--set", str(self.set), "--corpus",
                               str(self.root / "tune"), "--lipsync", str(self.fake), *extra],
                              capture_output=True, text=True)

    def test_finds_the_best_bias_and_writes_it_into_the_set(self):
        r = self.fit("--write")
        self.assertEqual(r.returncode, 0, r.stderr)
        written = json.loads(self.set.read_text())
        self.assertEqual(written["class_bias_db"], {"ah": -0.6, "w": 0.3})
        # Every other line as it was, the bias before the classes as `lipsync` orders it.
        lines = self.set.read_text().splitlines()
        self.assertIn("  0.17311000000000001", lines)
        self.assertLess(lines.index(' "class_bias_db": {'), lines.index(' "classes": []'))
        # Fitted again, the block is replaced, not added twice.
        r = self.fit("--write")
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(self.set.read_text().count("class_bias_db"), 1)

    def test_a_set_laid_out_otherwise_still_gets_its_bias(self):
        # Written on one line by another tool: the whole set is written again, nothing lost.
        self.set.write_text(json.dumps({"classes": [], "analysis": {"bins": 32}}))
        r = self.fit("--write")
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn("written again whole", r.stderr)
        written = json.loads(self.set.read_text())
        self.assertEqual(written["class_bias_db"], {"ah": -0.6, "w": 0.3})
        self.assertEqual(written["analysis"], {"bins": 32})
        self.assertEqual(written["classes"], [])

    def test_a_move_worth_less_than_the_minimum_gain_is_not_kept(self):
        # From ah −0.3 the step to −0.6 adds 2.7 points: kept at 1, not at 3.
        r = self.fit("--min-gain", "3", "--steps", "0.3")
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(json.loads(r.stdout.splitlines()[-1]), {"ah": -0.3})

    def test_live_too_fits_the_bias_for_the_live_path_as_well(self):
        r = self.fit("--steps", "0.3")
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(json.loads(r.stdout.splitlines()[-1]), {"ah": -0.6, "w": 0.3})
        r = self.fit("--steps", "0.3", "--live-too")
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(json.loads(r.stdout.splitlines()[-1]), {"ah": -0.6, "bmp": -0.3, "w": 0.3})

    def test_a_failing_evaluation_is_reported(self):
        r = subprocess.run([sys.executable, str(FIT), "--set", str(self.set), "--corpus",
                            str(self.root / "missing"), "--lipsync", "/bin/false"],
                           capture_output=True, text=True)
        self.assertNotEqual(r.returncode, 0)
        self.assertIn("failed", r.stderr)


if __name__ == "__main__":
    unittest.main()
