#!/usr/bin/env python3
"""scripts/fotaq_clips.py: the parts of the clip-to-words mapping that need no game data (the
resource table, how a line is cut into clips, the text left after the control codes)."""
import struct
import sys
import tempfile
import unittest
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "scripts"))
import fotaq_clips  # noqa: E402


def bundle(entries):
    """A QTBL file holding `entries` (name, bytes), as ScummVM's compress_queen lays it out."""
    table_end = 15 + 21 * len(entries)
    head = b"QTBL" + b"CEM10\0" + b"\0\0" + bytes([1]) + struct.pack(">H", len(entries))
    table, body, offset = b"", b"", table_end
    for name, data in entries:
        table += name.encode().ljust(12, b"\0") + bytes([1]) + struct.pack(">II", offset, len(data))
        body += data
        offset += len(data)
    return head + table + body


class ResourceTable(unittest.TestCase):
    def test_each_entry_is_found_at_its_offset_with_its_size(self):
        data = bundle([("020006J1.SB", b"mp3 one"), ("CHEF.DOG", b"dialogue")])
        table = fotaq_clips.read_table(data)
        self.assertEqual(set(table), {"020006J1.SB", "CHEF.DOG"})
        offset, size = table["CHEF.DOG"]
        self.assertEqual(data[offset:offset + size], b"dialogue")

    def test_a_file_that_is_not_a_bundle_is_refused(self):
        with self.assertRaises(ValueError):
            fotaq_clips.read_table(b"RIFF" + bytes(40))

    def test_a_bundle_without_the_games_text_is_refused_by_name(self):
        with tempfile.TemporaryDirectory() as tmp:
            path = Path(tmp) / "queen.1c"
            path.write_bytes(bundle([("020006J1.SB", b"mp3 one")]))
            with self.assertRaisesRegex(ValueError, "QUEEN.JAS"):
                fotaq_clips.Queen(path)


class LinesIntoClips(unittest.TestCase):
    def test_every_control_code_ends_a_clip_and_positions_count_from_zero(self):
        pieces = fotaq_clips.split_segments("Hello there.*00How are you?*XY00(128,112)*FLBye")
        self.assertEqual(pieces,
                         [(0, "Hello there."), (1, "How are you?"), (2, ""), (3, "Bye")])

    def test_a_piece_that_is_not_spoken_still_takes_its_number(self):
        # "*GD" / "*GM" pieces have no clip, but the next piece is still clip 2 (index 1).
        self.assertEqual(fotaq_clips.split_segments("One*GDTwo*02"),
                         [(1, "Two")])

    def test_the_text_keeps_only_the_words(self):
        self.assertEqual(fotaq_clips.clean("Floda^_ @@ is  *here*"), "Floda is here")
        self.assertFalse(fotaq_clips.speakable(" ... !"))


if __name__ == "__main__":
    unittest.main()
