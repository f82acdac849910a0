#!/usr/bin/env python3
"""scripts/make-phoneme-maps.py: the generated maps shipped in config/phonemes are what the
script gives with this espeak-ng (reproducible shipped data), its IPA rules pick the class a
mouth needs."""
import importlib.util
import subprocess
import sys
import tomllib
import unittest
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
SCRIPT = ROOT / "scripts" / "make-phoneme-maps.py"


def load_script():
    spec = importlib.util.spec_from_file_location("make_phoneme_maps", SCRIPT)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


class MakePhonemeMapsTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.m = load_script()
        table = ROOT / "config/phonemes/ipa-multilingual.toml"
        cls.table = tomllib.loads(table.read_text(encoding="utf-8"))["map"]

    def test_shipped_maps_are_what_the_script_gives(self):
        run = subprocess.run([sys.executable, str(SCRIPT), "--check"], capture_output=True,
                             text=True)
        self.assertEqual(run.returncode, 0, run.stderr)

    def test_marks_that_do_not_move_the_mouth_are_looked_through(self):
        c = lambda ipa: self.m.class_of(ipa, self.table)
        self.assertEqual(c("ɛ̃"), "eh")    # nasal
        self.assertEqual(c("tʲ"), "d")     # palatalised
        self.assertEqual(c("uː"), "w")     # long
        self.assertEqual(c("aɪ"), "ay")    # a diphthong with a class of its own
        self.assertEqual(c("ɛʊ"), "eh")    # ... else its first vowel's
        self.assertEqual(c("pf"), "bmp")   # an affricate that closes the lips first
        self.assertIsNone(c("☃"))

    def test_pause_tokens_at_a_words_edges_are_dropped_not_inner_ones(self):
        self.assertEqual(self.m.trimmings(["", "a", "", "b", ""])[0], ["a", "", "b"])
        self.assertIn(["", "r", "a"], self.m.trimmings(["", "r", "a", ""]))

    def test_each_mnemonic_is_paired_with_its_ipa(self):
        found, unpaired = self.m.pairs("de", "Pferd")
        self.assertEqual(unpaired, 0)
        self.assertEqual(dict(found).get("pF"), "pf")

    def test_an_unknown_language_is_an_error(self):
        run = subprocess.run([sys.executable, str(SCRIPT), "xx"], capture_output=True, text=True)
        self.assertNotEqual(run.returncode, 0)
        self.assertIn("no lines for 'xx'", run.stderr)


if __name__ == "__main__":
    unittest.main()
