#!/usr/bin/env python3
"""scripts/label-real-speech.py: the parts that need no package or pocketsphinx (how a label's
outer edges are moved in over room tone, how segments are written, how a prompt's words are read,
and which recording of an asterisk prompt is aligned)."""
import importlib.util
import math
import random
import shutil
import struct
import subprocess
import sys
import tempfile
import unittest
import wave
from pathlib import Path

SCRIPT = Path(__file__).resolve().parents[2] / "scripts" / "label-real-speech.py"
spec = importlib.util.spec_from_file_location("label_real_speech", SCRIPT)
labeller = importlib.util.module_from_spec(spec)
spec.loader.exec_module(labeller)

RATE = 16000


def write_wav(path, pieces, offset=0):
    """pieces: (seconds, kind) with kind 'room' (a quiet 50 Hz hum), 'vowel' (a loud 200 Hz
    buzz with harmonics), 'hiss' (a faint fricative: white noise less than 10 dB over the room),
    'noisy room' (the hum and a louder hiss) or 'padding' (digital silence)."""
    rng = random.Random(1)
    samples, t = [], 0
    for seconds, kind in pieces:
        for _ in range(int(seconds * RATE)):
            x = 30 * math.sin(2 * math.pi * 50 * t / RATE) if kind != "padding" else 0
            if kind == "noisy room":
                x += rng.gauss(0, 300)
            if kind == "vowel":
                x += sum(4000 / k * math.sin(2 * math.pi * 200 * k * t / RATE) for k in range(1, 6))
            elif kind == "hiss":
                x += rng.gauss(0, 20)
            samples.append(max(-32768, min(32767, int(x + offset))))
            t += 1
    with wave.open(str(path), "wb") as w:
        w.setnchannels(1)
        w.setsampwidth(2)
        w.setframerate(RATE)
        w.writeframes(struct.pack(f"<{len(samples)}h", *samples))


class TrimToVoice(unittest.TestCase):
    def trimmed(self, pieces, segments, offset=0):
        with tempfile.TemporaryDirectory() as tmp:
            wav = Path(tmp) / "word.wav"
            write_wav(wav, pieces, offset)
            return labeller.trim_to_voice(segments, wav)

    def test_a_last_phone_running_into_the_room_ends_where_the_voice_does(self):
        # "ball": the aligner ran /l/ 0.2 s past the voice, into the room's hum
        pieces = [(0.3, "room"), (0.4, "vowel"), (0.5, "room")]
        got = self.trimmed(pieces, [(0.0, 0.3, "sil"), (0.3, 0.5, "ao"), (0.5, 0.9, "l"),
                                    (0.9, 1.2, "sil")])
        spoken = [s for s in got if s[2] != "sil"]
        self.assertEqual([s[2] for s in spoken], ["ao", "l"])
        self.assertAlmostEqual(spoken[-1][1], 0.7, delta=0.015)
        self.assertAlmostEqual(got[-1][1], 1.2)  # the stretch after it is silence, to the end

    def test_a_first_phone_begun_in_the_room_starts_with_the_voice(self):
        pieces = [(0.3, "room"), (0.4, "vowel"), (0.3, "room")]
        got = self.trimmed(pieces, [(0.0, 0.2, "sil"), (0.2, 0.7, "aa"), (0.7, 1.0, "sil")])
        self.assertAlmostEqual([s for s in got if s[2] == "aa"][0][0], 0.3, delta=0.015)

    def test_a_first_phone_begun_after_the_voice_starts_with_it(self):
        # "earth": pocketsphinx's silence covered the first 60 ms of the vowel
        pieces = [(0.3, "room"), (0.4, "vowel"), (0.3, "room")]
        got = self.trimmed(pieces, [(0.0, 0.36, "sil"), (0.36, 0.7, "er"), (0.7, 1.0, "sil")])
        self.assertAlmostEqual([s for s in got if s[2] == "er"][0][0], 0.3, delta=0.015)
        self.assertEqual(got[0], (0.0, got[1][0], "sil"))

    def test_an_edge_moves_out_no_further_than_max_extend(self):
        pieces = [(0.2, "room"), (0.8, "vowel"), (0.2, "room")]
        got = self.trimmed(pieces, [(0.0, 0.6, "sil"), (0.6, 0.8, "aa"), (0.8, 1.2, "sil")])
        aa = [s for s in got if s[2] == "aa"][0]
        self.assertAlmostEqual(aa[0], 0.6 - labeller.MAX_EXTEND, delta=0.015)

    def test_a_faint_fricative_cut_short_runs_on_to_its_end(self):
        pieces = [(0.3, "room"), (0.3, "vowel"), (0.3, "hiss"), (0.3, "room")]
        got = self.trimmed(pieces, [(0.0, 0.3, "sil"), (0.3, 0.6, "er"), (0.6, 0.8, "th"),
                                    (0.8, 1.2, "sil")])
        self.assertAlmostEqual([s for s in got if s[2] == "th"][0][1], 0.9, delta=0.015)

    def test_a_faint_fricative_at_the_end_is_kept(self):
        # "earth": the /th/ is hardly louder than the room; its zero crossings tell it apart
        pieces = [(0.3, "room"), (0.3, "vowel"), (0.3, "hiss"), (0.3, "room")]
        got = self.trimmed(pieces, [(0.0, 0.3, "sil"), (0.3, 0.6, "ah"), (0.6, 0.9, "z"),
                                    (0.9, 1.2, "sil")])
        self.assertIn((0.6, 0.9, "z"), got)

    def test_a_phone_wholly_in_the_room_becomes_silence(self):
        pieces = [(0.3, "room"), (0.3, "vowel"), (0.6, "room")]
        got = self.trimmed(pieces, [(0.0, 0.3, "sil"), (0.3, 0.6, "ih"), (0.6, 0.8, "r"),
                                    (0.8, 1.2, "sil")])
        self.assertNotIn("r", [s[2] for s in got])

    def test_digital_padding_around_a_noisy_room_is_not_taken_for_the_room(self):
        # klettres-en-gb: each recording padded with digital silence; its own room 35 dB louder
        pieces = [(0.3, "padding"), (0.3, "noisy room"), (0.4, "vowel"), (0.3, "noisy room"),
                  (0.3, "padding")]
        got = self.trimmed(pieces, [(0.0, 0.6, "sil"), (0.6, 1.0, "eh"), (1.0, 1.6, "sil")])
        eh = [s for s in got if s[2] == "eh"][0]
        self.assertAlmostEqual(eh[0], 0.6, delta=0.015)
        self.assertAlmostEqual(eh[1], 1.0, delta=0.015)

    def test_a_dc_offset_does_not_hide_the_voice(self):
        # a few recordings sit far from zero: measured about each frame's mean, the room is
        # still the room
        pieces = [(0.3, "room"), (0.4, "vowel"), (0.5, "room")]
        got = self.trimmed(pieces, [(0.0, 0.3, "sil"), (0.3, 0.9, "aa"), (0.9, 1.2, "sil")],
                           offset=8000)
        self.assertAlmostEqual([s for s in got if s[2] == "aa"][0][1], 0.7, delta=0.015)

    def test_pauses_between_words_are_left_as_aligned(self):
        pieces = [(0.2, "room"), (0.3, "vowel"), (0.3, "room"), (0.3, "vowel"), (0.2, "room")]
        segments = [(0.0, 0.2, "sil"), (0.2, 0.55, "aa"), (0.55, 0.75, "ih"),
                    (0.75, 0.8, "d"), (0.8, 1.1, "aa"), (1.1, 1.3, "sil")]
        self.assertEqual(self.trimmed(pieces, segments)[1:5], segments[1:5])


class SpeakerList(unittest.TestCase):
    """config/corpus/real-speakers.txt: every line's split is one the scripts know."""

    def load(self, text):
        with tempfile.TemporaryDirectory() as d:
            path = Path(d) / "speakers.txt"
            path.write_text(text)
            return labeller.load_speakers(path)

    def test_the_shipped_list_has_every_split(self):
        speakers = labeller.load_speakers(SCRIPT.parent.parent / "config/corpus/real-speakers.txt")
        self.assertEqual({split for _, split, _ in speakers}, {"train", "networks", "dev", "tune"})

    def test_a_tune_voice_is_read_with_its_source(self):
        self.assertEqual(self.load("# a comment\nfillets-cs-v  tune  fillets:cs:v  # the fish\n"),
                         [("fillets-cs-v", "tune", "fillets:cs:v")])

    def test_an_unknown_split_names_the_line(self):
        with self.assertRaises(SystemExit) as raised:
            self.load("klettres-en  dev  klettres:en\nsomeone  test  klettres:en\n")
        self.assertIn(":2: expected 'SPEAKER train|networks|dev|tune SOURCE'", str(raised.exception))


class WriteLab(unittest.TestCase):
    def rows(self, segments, duration):
        with tempfile.TemporaryDirectory() as tmp:
            lab = Path(tmp) / "x.lab"
            labeller.write_lab(lab, segments, duration)
            return [(float(a), float(b), c) for a, b, c in
                    (line.split("\t") for line in lab.read_text().splitlines())]

    def test_the_labels_cover_the_file_without_gaps(self):
        # pocketsphinx's times moved by half its window: the first starts 13 ms in
        rows = self.rows([(0.0128, 0.2128, "sil"), (0.2128, 0.4, "aa"), (0.45, 0.6, "d")], 0.7)
        self.assertEqual(rows[0][0], 0.0)
        for before, after in zip(rows, rows[1:]):
            self.assertEqual(before[1], after[0])
        self.assertEqual(rows[-1][1], 0.7)
        self.assertIn((0.4, 0.45, "sil"), rows)  # a real pause stays one

    def test_a_file_ending_within_a_millisecond_of_the_last_segment_gets_no_empty_one(self):
        rows = self.rows([(0.0, 0.583, "ah"), (0.583, 0.8201, "d"), (0.8201, 0.83, "sil")],
                         0.820125)
        for start, end, _ in rows:
            self.assertLess(start, end)

    def test_slivers_are_dropped_and_silences_merged(self):
        rows = self.rows([(0.0, 0.2, "sil"), (0.2, 0.8200, "z"), (0.8200, 0.8204, "sil"),
                          (0.8204, 0.871, "sil")], 0.871)
        self.assertEqual([r[2] for r in rows], ["sil", "z", "sil"])
        for start, end, _ in rows:
            self.assertLess(start, end)


class PromptWords(unittest.TestCase):
    """An English asterisk prompt's words, as the pronouncing dictionary will spell them."""

    def test_a_digit_is_read_as_its_word(self):
        # once dropped: "press" was then stretched over "press seven"
        self.assertEqual(labeller.words_of("Press 7 to delete this message."),
                         ["press", "seven", "to", "delete", "this", "message"])
        self.assertEqual(labeller.words_of("3D audio disabled"), ["three", "d", "audio", "disabled"])

    def test_a_longer_number_leaves_the_prompt_out(self):
        words = labeller.words_of("folder 10")
        self.assertEqual(labeller.spelling(words, {"folder": [["F", "OW", "L", "D", "ER"]]}), None)


@unittest.skipUnless(shutil.which("ffmpeg") and shutil.which("soxi"), "needs ffmpeg and sox")
class WidebandTwin(unittest.TestCase):
    """An asterisk prompt is aligned on its 16 kHz G.722 recording, the 8 kHz WAV kept as audio."""

    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        self.dir = Path(self.tmp.name)
        self.wav = self.dir / "prompt.wav"
        write_wav(self.wav, [(0.3, "room"), (0.5, "vowel"), (0.3, "room")])

    def tearDown(self):
        self.tmp.cleanup()

    def make_twin(self, seconds_more=0.0):
        wide = self.dir / "wide.wav"
        write_wav(wide, [(0.3, "room"), (0.5, "vowel"), (0.3 + seconds_more, "room")])
        subprocess.run(["ffmpeg", "-hide_banner", "-loglevel", "error", "-y", "-i", str(wide),
                        "-f", "g722", str(self.dir / "prompt.g722")], check=True)

    def test_a_prompt_with_a_g722_twin_is_heard_on_it(self):
        self.make_twin()
        heard = labeller.labelling_audio(self.wav, self.wav, 1.1, self.dir)
        self.assertNotEqual(heard, self.wav)
        with wave.open(str(heard)) as w:
            self.assertEqual(w.getframerate(), 16000)
            self.assertAlmostEqual(w.getnframes() / 16000, 1.1, delta=0.02)

    def test_a_prompt_without_one_is_heard_as_written(self):
        self.assertEqual(labeller.labelling_audio(self.wav, self.wav, 1.1, self.dir), self.wav)

    def test_a_twin_of_another_length_is_refused_by_name(self):
        self.make_twin(seconds_more=0.5)
        with self.assertRaises(SystemExit) as raised:
            labeller.labelling_audio(self.wav, self.wav, 1.1, self.dir)
        self.assertIn("prompt.g722 lasts", str(raised.exception))


if __name__ == "__main__":
    unittest.main()
