#!/usr/bin/env python3
"""The speech clips of Flight of the Amazon Queen (Debian: flight-of-the-amazon-queen) and the
words each one says, for scripts/label-real-speech.py (source `fotaq` in
config/corpus/real-speakers.txt): about 6,600 clips, 4.5 hours, dozens of characters.

    python3 scripts/fotaq_clips.py QUEEN1C > clips.tsv    # name, speaker, text; summary on stderr

queen.1c is ScummVM's compressed resource bundle of the game: a table ("QTBL", then 21 bytes an
entry: name, bundle, offset, size), speech as NAME.SB entries (MP3, 16 kbps, 11,025 Hz), and the
text in the dialogue trees (*.DOG), Joe's object descriptions (QUEEN.JAS, QUEEN2.JAS) and the
cutscenes (*.CUT). The layouts and the voice-file naming were read from ScummVM's Queen engine
(engines/queen: resource.cpp, talk.cpp, cutaway.cpp, logic.cpp); this parser is our own.

How a clip is named after the line it says:
- A line is split at its '*' control codes ("*02", "*FL", "*XY00(x,y)"); each piece between codes
  is its own clip, numbered 1, 2, ... in one hex digit, counting pieces that are empty or not
  spoken ("*GD", "*GM") too.
- Dialogue (*.DOG): "%2d%4xJ<n>" for Joe's line (the file's talk key, the line's id in hex),
  "%2d%4xP<n>" for the other person's, "%2dSSSSJ<n>" for Joe's opening line, "%2dXXXXP<n>" /
  "%2dXXXXJ<n>" for greetings when talked to before; spaces become '0'.
- Joe's descriptions (QUEEN2.JAS): "JOE%04d<n>", the number a stock response (1..40) or 40 + the
  object description's.
- Cutscenes (*.CUT): the file's base name padded with '_' to 5 characters, the object's number
  ("%02d"), the piece; a text-only object has one clip, "...1", for its whole string.
Checked when written: over all mapped clips, text length against clip duration r = 0.83 (0.00 with
the texts shuffled), a median 12.5 characters a second.
"""
import re
import struct
import sys

DOG_HEADER = 20
JAS_HEADER = 20
CUT_HEADER = 20
JOE_RESPONSE_MAX = 40

# DOG file stems (trailing digits stripped) -> character code; checked against
# the lines themselves ("Howdy boy, the name's Jimmy Cook" is JIM1.DOG, TAM*.DOG
# is Mary-Lou, LOU*.DOG is Skip, ...) and against cutaways that open the DOG.
SPEAKER_ALIAS = {
    "and": "anderson", "bob": "trader_bob", "sec": "secretary",
    "prin": "princess_azura", "azura_obj": "princess_azura",
    "oracle": "guardian", "jim": "jimmy", "tam": "mary-lou", "lou": "skip",
    "joe_king": "joe",
}


def dog_speaker(stem):
    stem = stem.lower()
    if stem in ("man1", "man2"):          # two different men
        return stem
    base = stem.rstrip("0123456789") or stem
    return SPEAKER_ALIAS.get(base, base)


# --------------------------------------------------------------------------
# resource table
def read_table(data):
    if data[:4] != b"QTBL":
        raise ValueError("not a QTBL resource file")
    n = struct.unpack(">H", data[13:15])[0]
    ents = {}
    for k in range(n):
        o = 15 + 21 * k
        name = data[o:o + 12].split(b"\0")[0].decode("latin-1")
        off, size = struct.unpack(">II", data[o + 13:o + 21])
        ents[name.upper()] = (off, size)
    return ents


def _s16(b, o):
    return struct.unpack_from(">h", b, o)[0]


def _u16(b, o):
    return struct.unpack_from(">H", b, o)[0]


def get_string(buf, off, align=2):
    """Pascal string (length byte) padded to `align`; returns (text, newoff)."""
    n = buf[off]
    off += 1
    if n == 0:
        return "", off
    s = buf[off:off + n].decode("latin-1")
    off = (off + n + align - 1) & ~(align - 1)
    return s, off


# --------------------------------------------------------------------------
# sentence splitting (mirrors how the engine cuts a line into voice pieces)
def split_segments(sentence):
    """(piece index, text) for each spoken piece of a line."""
    out = []
    seg_idx = 0
    seg_start = 0
    i = 0
    n = len(sentence)
    while i < n:
        if sentence[i] == "*":
            text = sentence[seg_start:i]
            i += 1
            code = sentence[i:i + 2]
            if code == "XY":
                i += 11
            i += 2
            if code not in ("GD", "GM"):     # these are not spoken
                out.append((seg_idx, text))
            seg_idx += 1
            seg_start = i
        else:
            i += 1
    if seg_start < n:
        out.append((seg_idx, sentence[seg_start:]))
    return out


_ws = re.compile(r"\s+")


def clean(text):
    t = text.replace("^_", "").replace("@@", " ").replace("*", " ")
    t = _ws.sub(" ", t).strip()
    return t


def speakable(text):
    return re.search(r"[A-Za-z]", text) is not None


# --------------------------------------------------------------------------
class Queen:
    def __init__(self, path):
        with open(path, "rb") as f:
            self.data = f.read()
        try:
            self.ents = read_table(self.data)
            self.clipnames = {n[:-3]: v for n, v in self.ents.items() if n.endswith(".SB")}
            self._read_jas()
        except (struct.error, KeyError) as e:  # a cut-off file or one without the game's text
            raise ValueError(f"truncated or incomplete bundle ({e})") from e

    def res(self, name, skip=0):
        off, size = self.ents[name.upper()]
        return self.data[off + skip:off + size]

    # ---------------- JAS
    def _read_jas(self):
        jas = self.res("QUEEN.JAS", JAS_HEADER)
        self.num_rooms, self.num_names, self.num_objects, self.num_desc = \
            struct.unpack_from(">HHHH", jas, 0)
        p = 8
        self.objects = [None]
        for _ in range(self.num_objects):
            self.objects.append(struct.unpack_from(">hHHHhHHh", jas, p))
            p += 16
        txt = self.res("QUEEN2.JAS").decode("latin-1")
        lines = txt.split("\r\n")
        # Descriptions, object names, room names, 12 verbs, then Joe's stock responses.
        self.descriptions = lines[:self.num_desc]
        self.names = lines[self.num_desc:self.num_desc + self.num_names]
        o = self.num_desc + self.num_names + self.num_rooms + 12
        self.joe_responses = lines[o:o + JOE_RESPONSE_MAX]

    def object_name(self, objnum):
        if 0 < objnum < len(self.objects):
            nm = abs(self.objects[objnum][0])
            if 0 < nm <= len(self.names):
                return self.names[nm - 1]
        return None

    # ---------------- emit helpers
    def _emit(self, out, prefix, sentence, speaker, whole=False):
        prefix = prefix.replace(" ", "0")
        segs = [(0, sentence)] if whole else split_segments(sentence)
        for idx, text in segs:
            if idx > 15:
                continue
            name = (prefix + "%x" % (idx + 1)).upper()
            t = clean(text)
            if not speakable(t):
                continue
            if name not in self.clipnames:
                continue
            out.setdefault(name, (t, speaker))

    # ---------------- JOE descriptions
    def joe_clips(self, out):
        for i, s in enumerate(self.joe_responses, 1):
            self._emit(out, "JOE%04d" % i, s, "joe")
        for i, s in enumerate(self.descriptions, 1):
            if s.upper().endswith(".CUT"):
                continue
            self._emit(out, "JOE%04d" % (i + JOE_RESPONSE_MAX), s, "joe")

    # ---------------- DOG dialogues
    def parse_dog(self, name):
        b = self.res(name, DOG_HEADER)
        level_max = abs(_s16(b, 0))
        talk_key, jmax, pmax = struct.unpack_from(">hhh", b, 4)
        p1 = _u16(b, 22)
        p2 = _u16(b, 26)
        joe_off = 32 + level_max * 96

        def read_list(off, count):
            res = []
            for _ in range(count):
                off += 2
                ident = _s16(b, off)
                off += 2
                s, off = get_string(b, off, 4)
                res.append((ident, s))
            return res

        joe = read_list(joe_off, jmax)
        per = read_list(p1, pmax)
        off = p2
        person2, off = get_string(b, off, 2)
        joe2, off = get_string(b, off, 2)
        return talk_key, joe, per, person2, joe2

    def dog_clips(self, out):
        for name in sorted(n for n in self.ents if n.endswith(".DOG")):
            stem = dog_speaker(name[:-4])
            try:
                key, joe, per, person2, joe2 = self.parse_dog(name)
            except (struct.error, IndexError):
                continue
            for ident, s in joe:
                if ident == 0:
                    pre = "%2dSSSSJ" % key
                else:
                    pre = "%2d%4xJ" % (key, ident & 0xFFFF)
                self._emit(out, pre, s, "joe")
            for ident, s in per:
                pre = "%2d%4xP" % (key, ident & 0xFFFF)
                self._emit(out, pre, s, stem)
            if person2:
                self._emit(out, "%2dXXXXP" % key, person2, stem)
            if joe2:
                self._emit(out, "%2dXXXXJ" % key, joe2, "joe")

    # ---------------- CUT cutscenes
    def parse_cut(self, name):
        b = self.res(name, CUT_HEADER)
        count = abs(_s16(b, 2))
        next_sentence = _u16(b, 8)
        _, off = get_string(b, next_sentence, 2)  # the cutscene's entry point, not spoken
        sentences = []
        for _ in range(count):
            s, off = get_string(b, off, 2)
            sentences.append(s)
        return sentences, self._walk_cut_objects(b, count)

    def _walk_cut_objects(self, b, count):
        """Return list of (objectNumber) per cutaway object, or None when the
        object records cannot be walked unambiguously."""
        p = 12
        objs = []
        try:
            for _ in range(count):
                v = struct.unpack_from(">17h", b, p)
                p += 34
                objnum, anim_list, execute, from_obj = v[0], v[4], v[5], v[12]
                pc = _s16(b, p)
                p += 2 + 2 * max(pc, 0)
                # object type as the engine decides it
                typ = "anim"
                if objnum > 0:
                    if not anim_list and objnum < len(self.objects) and \
                            self.objects[objnum][7] in (-3, -4):
                        typ = "person"
                elif objnum in (0, -1):
                    if not anim_list:
                        typ = "person"
                if from_obj > 0:
                    typ = "noanim"
                if objnum in (-2, -3):
                    typ = "text"
                elif objnum == -4:
                    typ = "textdisplay"
                if typ == "anim" and not execute:
                    typ = "noanim"
                if typ == "anim":
                    while True:
                        h = _s16(b, p)
                        p += 2
                        if h == -2:
                            break
                        if h > 1000:
                            return None
                        p += 18
                objs.append((objnum, typ))
        except struct.error:
            return None
        return objs

    def cut_clips(self, out):
        for name in sorted(n for n in self.ents if n.endswith(".CUT")):
            base = name[:-4]
            pad = base + "_" * max(0, 5 - len(base))
            try:
                sentences, objs = self.parse_cut(name)
            except (struct.error, IndexError):
                continue
            for i, s in enumerate(sentences, 1):
                if not s or s == "*" or s.startswith("#"):
                    continue
                pre = "%s%02d" % (pad, i)
                speaker = "cut"
                whole = False
                if objs is not None and i - 1 < len(objs):
                    objnum, typ = objs[i - 1]
                    if typ == "text":
                        whole = True
                        speaker = "caption"
                    elif typ == "person":
                        if objnum in (0, -1):
                            speaker = "joe"
                        else:
                            nm = self.object_name(objnum)
                            speaker = nm.lower().replace(" ", "_") if nm else "obj%d" % objnum
                            speaker = SPEAKER_ALIAS.get(speaker, speaker)
                    else:
                        continue        # not spoken in this cutaway
                self._emit(out, pre, s, speaker, whole=whole)

    def all_clips(self):
        out = {}
        self.dog_clips(out)
        self.joe_clips(out)
        self.cut_clips(out)
        res = []
        for name in sorted(out):
            text, speaker = out[name]
            off, size = self.clipnames[name]
            res.append({"name": name, "offset": off, "size": size, "text": text,
                        "speaker": speaker})
        return res


def category(name):
    if name.startswith("JOE"):
        return "JOE"
    if name.startswith("C") and not name[:2].isdigit():
        return "CUT(C...)"
    m = re.match(r"^[0-9 ]{2}(....)([JP])", name)
    if m:
        if m.group(1) == "SSSS":
            return "DOG-SSSS"
        if m.group(1) == "XXXX":
            return "DOG-XXXX"
        return "DOG-" + m.group(2)
    return "other:" + re.sub(r"[0-9]", "", name)[:3]


def main(argv):
    if len(argv) < 2:
        print("usage: fotaq_clips.py QUEEN1C > clips.tsv", file=sys.stderr)
        return 2
    try:
        q = Queen(argv[1])
    except (OSError, ValueError) as e:
        print(f"fotaq_clips.py: {argv[1]}: not Flight of the Amazon Queen's queen.1c ({e})",
              file=sys.stderr)
        return 1
    res = q.all_clips()
    for c in res:
        print("%s\t%s\t%s" % (c["name"], c["speaker"], c["text"].replace("\t", " ")))
    mapped = {c["name"] for c in res}
    tot = {}
    got = {}
    for n in q.clipnames:
        k = category(n)
        tot[k] = tot.get(k, 0) + 1
        if n in mapped:
            got[k] = got.get(k, 0) + 1
    print("mapped %d of %d speech clips" % (len(mapped), len(q.clipnames)), file=sys.stderr)
    for k in sorted(tot):
        print("  %-12s %5d / %5d" % (k, got.get(k, 0), tot[k]), file=sys.stderr)
    print("distinct speakers: %d" % len({c["speaker"] for c in res}), file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
