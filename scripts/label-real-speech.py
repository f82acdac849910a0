#!/usr/bin/env python3
"""Labels recordings of real people for training and evaluation (run by fetch-real-speech.sh).

    label-real-speech.py ROOT OUT_DIR [--subset N] [--speakers a,b]

ROOT is where the Debian packages were unpacked (dpkg -x). The speakers, their split and their
source are read from config/corpus/real-speakers.txt. Every item becomes
OUT_DIR/SPLIT/SPEAKER/NAME.wav (16 kHz mono 16-bit, by sox), NAME.lab (common-set labels) and
NAME.txt (the words spoken, for `lipsync align` and `lipsync eval --align`).

Labels:
- words known (English): forced alignment with pocketsphinx and its en-us model, a development
  tool only (the product never depends on it). Each ARPAbet phone is a "word" of a JSGF grammar
  that spells the transcript (every dictionary pronunciation allowed, optional pauses), so the
  decoder's word times are phone times. Phones map to the common set by config/phonemes/arpabet.toml.
  Its times are moved to the centre of its analysis window (POCKETSPHINX_HALF_WINDOW), and the
  words' outer edges then to where the sound starts and stops (trim_to_voice, below). The
  British klettres speaker's letters are spelled from espeak-ng's en-gb reading ("zed").
- words known in Italian or Spanish (asterisk prompts): the same aligner, each word spelled in
  the nearest English phones from espeak-ng's phonemisation (config/corpus/espeak-arpabet.toml).
- asterisk prompts (every language) are aligned on their 16 kHz G.722 recording (decoded by
  ffmpeg; pocketsphinx's model is a 16 kHz one), and their 8 kHz WAV is the audio written.
- fillets-ng (Czech, Dutch): the game's dialogue clips, whose words are in its scripts
  (script/LEVEL/dialogs_LANG.lua, keyed by clip name); one voice a speaker, by the clip name's
  middle part (`v` the big fish, a man; `m` the small fish, a woman); aligned as the asterisk
  prompts of other languages are. At most FILLETS_MAX_ITEMS clips a voice (sorted by name): the
  labelling time stays bounded and the voice still outweighs none of the others.
- festvox-ru: the voice's own time-aligned phone labels (lab/*.lab), mapped by
  config/phonemes/festvox-ru.toml.
- tuxpaint (tuxpaint-stamps-default): each stamp's description read aloud (NAME_desc_LANG.ogg,
  44.1 kHz), its words in the stamp's NAME.txt (the `LANG.utf8=` line). Written as NAME.wav +
  NAME.txt only, without labels: scripts/train-templates.sh labels them with the project's own
  aligner (`lipsync align --voice LANG`), on templates trained without them.
- fotaq (flight-of-the-amazon-queen): the game's dialogue, each clip's words from the game's own
  text (scripts/fotaq_clips.py); written as NAME.wav + NAME.txt and labelled by the project's
  aligner, as tuxpaint is. Needs sox's MP3 format (libsox-fmt-mp3).
Items whose words are not in the dictionary, or that the aligner cannot fit, are skipped and
counted. Reproducible: same packages, same tools, same files.
"""
import argparse
import array
import gzip
import math
import os
import re
import subprocess
import sys
import tempfile
import tomllib
import wave
from pathlib import Path

HERE = Path(__file__).resolve().parent.parent
MODEL = Path("/usr/share/pocketsphinx/model/en-us")
ARPABET = ("AA AE AH AO AW AY B CH D DH EH ER EY F G HH IH IY JH K L M N NG OW OY P R S SH T TH "
           "UH UW V W Y Z ZH").split()


def log(msg):
    print(f"label-real-speech: {msg}", file=sys.stderr)


def load_map(name):
    doc = tomllib.loads((HERE / "config/phonemes" / f"{name}.toml").read_text())
    table = dict(doc.get("map", {}))
    table.update(doc.get("nearest", {}))
    return {k.lower(): v for k, v in table.items()} if not doc.get("case_sensitive") else table


def load_speakers(path):
    speakers = []
    for n, line in enumerate(path.read_text().splitlines(), 1):
        line = line.split("#", 1)[0].strip()
        if not line:
            continue
        fields = line.split()
        if len(fields) != 3 or fields[1] not in ("train", "networks", "dev", "tune"):
            sys.exit(f"{path}:{n}: expected 'SPEAKER train|networks|dev|tune SOURCE', got '{line}'")
        speakers.append(tuple(fields))
    return speakers


# --- sources: each yields (name, audio path, words or None, ready labels or None, text) -------
# text: the words spoken as a script would give them (NAME.txt).

DIGITS = "zero one two three four five six seven eight nine".split()


def words_of(text):
    """The words of an English prompt, a digit read as its word ("press 7": press seven). A
    longer number ("H.323", "folder 10") is read in more than one way: it gives a word that no
    dictionary has, so the prompt is left out rather than labelled without it (the digits were
    once dropped, and the words around them stretched over the number)."""
    text = re.sub(r"\[[^\]]*\]", " ", text.lower())
    text = re.sub(r"\d{2,}", " <number> ", text)
    text = re.sub(r"\d", lambda d: f" {DIGITS[int(d.group())]} ", text)
    return re.findall(r"<number>|[a-z']+", text.replace("-", " "))


def asterisk_items(root, voice, lang):
    base = root / "usr/share/asterisk/sounds" / voice
    txt = root / f"usr/share/doc/asterisk-core-sounds-{lang}/core-sounds-{lang}.txt.gz"
    with gzip.open(txt, "rt", encoding="utf-8-sig") as f:
        for line in f:
            if line.startswith(";") or ":" not in line:
                continue
            key, text = line.split(":", 1)
            key = key.strip()
            audio = base / f"{key}.wav"
            if audio.exists() and "[" not in text:
                if wideband_twin(audio) is None:
                    sys.exit(f"label-real-speech: {audio.with_suffix('.g722')} missing: "
                             f"asterisk-core-sounds-{lang}-g722 is needed (fetch-real-speech.sh)")
                words = words_of(text) if lang == "en" else ("espeak", lang, text.strip())
                yield key.replace("/", "_"), audio, words, None, text.strip()


def klettres_items(root, lang):
    base = root / "usr/share/klettres" / lang
    for sub in ("alpha", "syllab"):
        for audio in sorted((base / sub).glob("*.ogg")):
            word = audio.stem.lower()
            # The British speaker says the letters as British English does ("zed", "ar"), which
            # the American dictionary does not have: spelled from espeak-ng's en-gb reading.
            words = ("espeak", "en-gb", word) if lang == "en_GB" else [word]
            yield f"{sub}_{audio.stem}", audio, words, None, word


def ktuberling_items(root, lang):
    words = {}
    table = HERE / "config/corpus/ktuberling-en-words.txt"
    for line in table.read_text().splitlines():
        if line.strip() and not line.startswith("#"):
            key, text = line.split(":", 1)
            words[key.strip()] = text.split()
    for audio in sorted((root / "usr/share/ktuberling/sounds" / lang).glob("*.ogg")):
        if audio.stem in words:
            yield audio.stem, audio, words[audio.stem], None, " ".join(words[audio.stem])


FILLETS_MAX_ITEMS = 300


def fillets_items(root, lang, voice):
    base = root / "usr/share/games/fillets-ng"
    items = []
    for script in sorted((base / "script").glob(f"*/dialogs_{lang}.lua")):
        level = script.parent.name
        key = None
        for line in script.read_text(encoding="utf-8").splitlines():
            if m := re.match(r'\s*dialogId\("([^"]+)"', line):
                key = m.group(1)
            elif (m := re.match(r'\s*dialogStr\("(.*)"\)\s*$', line)) and key:
                parts = key.split("-")
                audio = base / "sound" / level / lang / f"{key}.ogg"
                if len(parts) >= 3 and parts[1] == voice and audio.exists():
                    items.append((f"{level}_{key}", audio, m.group(1).replace('\\"', '"')))
                key = None
    for name, audio, text in sorted(items)[:FILLETS_MAX_ITEMS]:
        yield name, audio, ("espeak", lang, text), None, text


def festvox_ru_items(root):
    base = root / "usr/share/festival/voices/russian/msu_ru_nsh_clunits"
    phones = load_map("festvox-ru")
    texts = {}  # etc/txt.done.data: ( ru_0001 "text" ), '+' before a stressed vowel
    for line in (base / "etc/txt.done.data").read_text(encoding="utf-8").splitlines():
        m = re.match(r'\(\s*(\S+)\s+"(.*)"\s*\)', line)
        if m:
            texts[m.group(1)] = m.group(2).replace("+", "")
    for lab in sorted((base / "lab").glob("*.lab")):
        segments, start = [], 0.0
        for line in lab.read_text().splitlines():
            fields = line.split()
            if len(fields) != 3:
                continue
            end = float(fields[0])
            if fields[2] not in phones:
                sys.exit(f"{lab}: phone '{fields[2]}' is not in config/phonemes/festvox-ru.toml")
            segments.append((start, end, phones[fields[2]]))
            start = end
        yield lab.stem, base / "wav" / f"{lab.stem}.wav", None, segments, texts.get(lab.stem)


# Written beside each speaker's files; labels an older labeller made (another version) are made
# again. Raise it whenever the labels would come out otherwise.
# 2: pocketsphinx's times at its window's centre, the words' outer edges where the sound is.
# 3: the asterisk prompts aligned on their 16 kHz recording (wideband_twin), English digits read.
LABELLER_VERSION = "3"

# Items whose labels come from the project's own aligner later (train-templates.sh), not here.
BY_ALIGNER = "aligner"


def tuxpaint_items(root, lang):
    base = root / "usr/share/tuxpaint/stamps"
    suffix = f"_desc_{lang}.ogg"
    for audio in sorted(base.rglob(f"*{suffix}")):
        stem = audio.name[: -len(suffix)]
        about = audio.parent / f"{stem}.txt"
        if not about.exists():
            continue
        lines = about.read_text(encoding="utf-8", errors="replace").splitlines()
        text = next((l.split("=", 1)[1].strip() for l in lines if l.startswith(f"{lang}.utf8=")), "")
        if text:
            name = "_".join(audio.parent.relative_to(base).parts + (stem,))
            yield name, audio, BY_ALIGNER, None, text


# Flight of the Amazon Queen's dialogue (scripts/fotaq_clips.py): dozens of English actors, as
# 16 kbps MP3 at 11 kHz. At most FOTAQ_MAX_PER_SPEAKER clips a character (in name order), so
# that Joe, who says 2,790, does not outweigh everyone else (250: 3,153 clips, 1,722 placed by
# the aligner; at 40, 1,261 and 638; docs/measurements.md, "fotaq and nine readers in the
# networks"); sounds ("(sigh)", "<koff>"),
# spelled letters, shouted codes and lines under three words are left out, and so are the
# cutscene "speakers" that are captions or objects. Labelled later by the project's own aligner
# (train-templates.sh), like tuxpaint: pocketsphinx's en-us model misreads this audio.
FOTAQ_MAX_PER_SPEAKER = 250
FOTAQ_NOT_SPEAKERS = {"caption", "note", "path", "smoke", "telephone", "door", "torch", "rock",
                      "lily_pad"}


def fotaq_items(root):
    sys.path.insert(0, str(HERE / "scripts"))
    import fotaq_clips
    bundle = root / "usr/share/scummvm/flight-of-the-amazon-queen/queen.1c"
    try:
        game = fotaq_clips.Queen(bundle)
    except (OSError, ValueError) as e:
        sys.exit(f"{bundle}: cannot read the game's clips ({e})")
    clips_dir = root / "fotaq-clips"  # each clip as an MP3 file, for sox
    clips_dir.mkdir(exist_ok=True)
    per_speaker = {}
    for clip in game.all_clips():  # in name order
        speaker, text = clip["speaker"], clip["text"]
        if speaker in FOTAQ_NOT_SPEAKERS or per_speaker.get(speaker, 0) >= FOTAQ_MAX_PER_SPEAKER:
            continue
        if re.search(r"[()<>\[\]]", text) or not re.search(r"[a-z]{2}", text) or len(text.split()) < 3:
            continue
        per_speaker[speaker] = per_speaker.get(speaker, 0) + 1
        audio = clips_dir / f"{clip['name']}.mp3"
        if not audio.exists():
            audio.write_bytes(game.data[clip["offset"]:clip["offset"] + clip["size"]])
        yield clip["name"], audio, BY_ALIGNER, None, text


def items_of(root, source):
    kind, *args = source.split(":")
    if kind == "asterisk":
        return asterisk_items(root, *args)
    if kind == "klettres":
        return klettres_items(root, *args)
    if kind == "ktuberling":
        return ktuberling_items(root, *args)
    if kind == "fillets":
        return fillets_items(root, *args)
    if kind == "festvox-ru":
        return festvox_ru_items(root)
    if kind == "tuxpaint":
        return tuxpaint_items(root, *args)
    if kind == "fotaq":
        return fotaq_items(root)
    sys.exit(f"config/corpus/real-speakers.txt: unknown source '{source}'")


# --- forced alignment with pocketsphinx ------------------------------------------------------

def load_dictionary():
    prons = {}
    for line in (MODEL / "cmudict-en-us.dict").read_text(errors="replace").splitlines():
        word, *phones = line.split()
        prons.setdefault(re.sub(r"\(\d+\)$", "", word), []).append(phones)
    return prons


def espeak_spelling(lang, text):
    """Per word, the one pronunciation espeak-ng gives, in ARPAbet (config/corpus/espeak-arpabet.toml)."""
    doc = tomllib.loads((HERE / "config/corpus/espeak-arpabet.toml").read_text())
    table = doc["map"] | doc.get("lang", {}).get(lang, {})
    out = subprocess.run(["espeak-ng", "-q", "-x", "--sep= ", "-v", lang, text],
                         capture_output=True, text=True, check=True).stdout
    words = []
    for word in re.split(r"\s{2,}|\n", out):
        phones = []
        for token in word.split():
            token = re.sub(r"[',:;]|\(\w+\)", "", token)  # stress, length; (en) language switches
            if not token or token.startswith("_"):
                continue
            if token not in table:
                return None  # a sound the table does not know: leave the prompt out
            phones += table[token].split()
        if phones:
            words.append([phones])
    return words


def spelling(words, prons):
    """Per word, its pronunciations (ARPAbet lists); None when a word cannot be spelled."""
    if isinstance(words, tuple):
        return espeak_spelling(words[1], words[2])
    if not words or any(w not in prons for w in words):
        return None
    return [prons[w] for w in words]


def grammar(spelled):
    """JSGF spelling the words phone by phone; every pronunciation allowed, pauses optional."""
    parts = []
    for alternatives in spelled:
        alts = [" ".join("ph_" + p.lower() for p in pron) for pron in alternatives]
        parts.append("(" + " | ".join(alts) + ")")
    body = " [sil] ".join(parts)
    return f"#JSGF V1.0;\ngrammar align;\npublic <s> = [sil] {body} [sil];\n"


# pocketsphinx reports frame k at k * 10 ms, the start of the window (-wlen 0.025625 s, its
# default) whose features decided it; the centre of that window, half of it later, is where the
# sound was. Our aligner's boundaries on the English dev words lay a median 8 ms (ktuberling) and
# 8 to 13 ms (klettres) after pocketsphinx's at vowel-consonant changes, in both directions,
# and within a few milliseconds of festvox-ru's own labels either way (a median -4 ms into a
# vowel, +6 ms out of one): the shift is pocketsphinx's.
POCKETSPHINX_HALF_WINDOW = 0.025625 / 2


def align(wav, spelled, work, phones):
    (work / "g.jsgf").write_text(grammar(spelled))
    cmd = ["pocketsphinx_continuous", "-infile", str(wav), "-hmm", str(MODEL / "en-us"),
           "-dict", str(work / "ph.dict"), "-jsgf", str(work / "g.jsgf"), "-time", "yes",
           "-remove_silence", "no", "-fsgusefiller", "no", "-beam", "1e-80", "-pbeam", "1e-80", "-wbeam", "1e-60",
           "-logfn", os.devnull]
    out = subprocess.run(cmd, capture_output=True, text=True).stdout
    segments = []
    for line in out.splitlines():
        fields = line.split()
        if len(fields) != 4 or fields[1][0].isalpha():
            continue
        # pocketsphinx stamps a frame with the start of its 25.6 ms window: the sound it heard
        # there lies half a window later (see POCKETSPHINX_HALF_WINDOW).
        word = fields[0]
        start = float(fields[1]) + POCKETSPHINX_HALF_WINDOW
        end = float(fields[2]) + 0.01 + POCKETSPHINX_HALF_WINDOW
        if word.startswith("ph_"):
            name = phones[word[3:]]
        elif word in ("<sil>", "sil", "<s>", "</s>") or word.startswith("["):
            name = "sil"
        else:
            continue
        segments.append((start, end, name))
    return segments


# --- what pocketsphinx hears ----------------------------------------------------------------------
# The asterisk prompts' WAVs are 8 kHz telephone sound, and pocketsphinx's en-us model reads
# 16 kHz speech up to 6.8 kHz (its feat.params): on them it stretched phones over whole words
# ("hello": /ə/ 390 ms, no /oʊ/). The same recordings are packaged as 16 kHz G.722
# (asterisk-core-sounds-LANG-g722, of the same length to the sample), so the labels are made on
# those, decoded by ffmpeg, and the 8 kHz WAV stays the audio trained and scored on. Our aligner
# (left-out templates) agreed with asterisk-en-allison's labels on 60.5 % of frames' visual
# groups before, 67.4 % after; its audio-only jaw r against them rose from 0.66 to 0.76.
def wideband_twin(audio):
    """The 16 kHz G.722 recording of an 8 kHz asterisk prompt, when it is unpacked beside it."""
    twin = audio.with_suffix(".g722")
    return twin if audio.suffix == ".wav" and twin.exists() else None


def labelling_audio(audio, wav, duration, work):
    """What pocketsphinx aligns: the wideband twin when there is one, else the WAV written."""
    twin = wideband_twin(audio)
    if twin is None:
        return wav
    heard = work / "wideband.wav"
    try:
        subprocess.run(["ffmpeg", "-hide_banner", "-loglevel", "error", "-y", "-f", "g722",
                        "-i", str(twin), "-ar", "16000", "-ac", "1", "-sample_fmt", "s16",
                        str(heard)], check=True)
    except (OSError, subprocess.CalledProcessError) as e:
        sys.exit(f"label-real-speech: {twin}: cannot decode with ffmpeg ({e})")
    info = subprocess.run(["soxi", "-D", str(heard)], capture_output=True, text=True, check=True)
    if abs(float(info.stdout) - duration) > 0.02:
        sys.exit(f"label-real-speech: {twin} lasts {float(info.stdout):.3f} s, "
                 f"{audio} {duration:.3f} s: not the same recording")
    return heard


# --- the room before and after the words --------------------------------------------------------
# pocketsphinx's silence model does not fit every room: on the ktuberling words it ran the last
# phone a median 60 ms (a tenth of the words, 170 ms or more) into room tone after the voice had
# stopped, and began the first 40 ms early ("ball": /l/ to 0.75 s, the voice gone at 0.63 s and
# the room hum alone after it); elsewhere it began a word 60 to 80 ms after the voice ("earth",
# "rocket": the first vowel's harmonics under its silence) and ended a faint final fricative
# where it was still heard ("earth": /θ/ to 0.49 s, its hiss to 0.63 s). So the outer edges of
# the words are moved to where the sound starts and stops: in over frames that are plainly room
# tone, out over frames that are plainly sound, up to MAX_EXTEND. Sound is a frame ROOM_DB over
# the room (the tenth percentile of the frames, digital silence aside: klettres-en-gb's files
# are padded with it around a recording 35 dB louder), or a fricative's zero crossings
# FRICATIVE_DB over it. Only the outer edges move; a phone left with no sound becomes silence;
# pauses between words stay the aligner's (an endpoint detector in the manner of Rabiner &
# Sambur 1975, with the room measured on the file's quieter frames).
ROOM_DB = 10.0          # dB above the room that is sound, whatever it is
FRICATIVE_DB = 4.0      # ... and that is sound with a fricative's zero crossings
ROOM_FRAMES = 10        # frames (heard, not padding) enough to measure the room
DIGITAL_SILENCE_DB = 6.0  # frames below this (an RMS of 2 in 16 bits) are padding, not a room
FRICATIVE_ZCR = 0.25    # zero crossings a sample above which a frame may be a fricative
MAX_EXTEND = 0.15       # seconds an edge may move out


def frame_levels(wav):
    """Per 10 ms frame of a 16-bit mono WAV: (level in dB, zero crossings a sample)."""
    with wave.open(str(wav)) as w:
        rate, data = w.getframerate(), array.array("h", w.readframes(w.getnframes()))
    if sys.byteorder == "big":
        data.byteswap()
    hop, levels = rate // 100, []
    for start in range(0, len(data) - hop + 1, hop):
        # about the frame's own mean: a few recordings (ktuberling's tv_*) carry a DC offset
        mean = sum(data[start:start + hop]) / hop
        frame = [v - mean for v in data[start:start + hop]]
        power = sum(v * v for v in frame) / hop
        crossings = sum((a < 0) != (b < 0) for a, b in zip(frame, frame[1:]))
        levels.append((10 * math.log10(power + 1e-3), crossings / hop))
    return levels


def room_level(levels):
    """The room's level: the tenth percentile of the frames, digital silence (padding a file was
    cut with, and its fade into the recording) aside, or of all of them where nearly every frame
    is such padding."""
    heard = sorted(db for db, _ in levels if db >= DIGITAL_SILENCE_DB)
    if len(heard) < ROOM_FRAMES:
        heard = sorted(db for db, _ in levels)
    return heard[len(heard) // 10]


def voice_edges(levels, first, last):
    """Where the sound around the words [first, last] s starts and stops, in seconds."""
    room = room_level(levels)

    def sound(i):
        db, zcr = levels[i]
        return db >= room + ROOM_DB or (zcr >= FRICATIVE_ZCR and db >= room + FRICATIVE_DB)

    n, reach = len(levels), int(round(MAX_EXTEND * 100))
    begin = min(int(round(first * 100)), n)
    if begin < n and sound(begin):  # out, over sound just before
        floor = max(0, begin - reach)
        while begin > floor and sound(begin - 1):
            begin -= 1
    else:  # in, over room
        while begin < n and not sound(begin):
            begin += 1
    end = min(int(round(last * 100)), n)
    if end > 0 and sound(end - 1):
        ceiling = min(n, end + reach)
        while end < ceiling and sound(end):
            end += 1
    else:
        while end > begin and not sound(end - 1):
            end -= 1
    return begin / 100, end / 100


def trim_to_voice(segments, wav):
    """segments with the words' outer edges moved to where the sound starts and stops (above)."""
    levels = frame_levels(wav)
    spoken = [i for i, s in enumerate(segments) if s[2] != "sil"]
    if len(levels) < 2 * ROOM_FRAMES or not spoken:
        return segments
    words = segments[spoken[0]:spoken[-1] + 1]
    voice_start, voice_end = voice_edges(levels, words[0][0], words[-1][1])
    words[0] = (min(words[0][0], voice_start),) + words[0][1:]
    words[-1] = words[-1][:1] + (max(words[-1][1], voice_end), words[-1][2])
    moved = [(segments[0][0], voice_start, "sil")]
    for start, stop, name in words:  # they tile [voice_start, voice_end] once clipped to it
        start, stop = max(start, voice_start), min(stop, voice_end)
        if stop - start < 0.01 and name != "sil":
            name = "sil"  # a phone left with no sound
        moved.append((start, stop, name))
    moved.append((voice_end, segments[-1][1], "sil"))
    return [s for s in moved if s[1] > s[0]]


def write_lab(path, segments, duration):
    merged = []
    # to the millisecond first, as written: a sliver shorter than that would read as a segment
    # that ends before it starts
    rounded = ((round(a, 3), round(b, 3), name) for a, b, name in segments)
    segments = [s for s in rounded if s[1] > s[0]]
    duration = round(duration, 3)
    for start, end, name in segments:
        if merged and merged[-1][2] == name and abs(merged[-1][1] - start) < 0.015:
            merged[-1] = (merged[-1][0], end, name)
        else:
            merged.append((start, end, name))
    with open(path, "w") as f:
        last = 0.0
        for start, end, name in merged:
            if start > last + 0.015:
                f.write(f"{last:.3f}\t{start:.3f}\tsil\n")
                last = start
            start = last  # a gap under 15 ms (or an overlap) goes to the segment after it
            end = min(end, duration)
            if end > start:
                f.write(f"{start:.3f}\t{end:.3f}\t{name}\n")
                last = end
        if duration > last + 0.015:
            f.write(f"{last:.3f}\t{duration:.3f}\tsil\n")


def write_text(path, text):
    if text and (not path.exists() or path.read_text(encoding="utf-8") != text + "\n"):
        path.write_text(text + "\n", encoding="utf-8")


def convert(src, dst):
    # -R: sox dithers with a fixed seed, so the same package gives the same WAV (and the same
    # labels) on every run; without it the dither differs, and pocketsphinx places a few
    # marginal files on one run and not on the next.
    # -V1: no warnings (fotaq's MP3 decodes a sample or two past full scale, which sox clips).
    subprocess.run(["sox", "-R", "-q", "-V1", str(src), "-r", "16000", "-c", "1", "-b", "16", str(dst)],
                   check=True)
    info = subprocess.run(["soxi", "-D", str(dst)], capture_output=True, text=True, check=True)
    return float(info.stdout)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("root", type=Path)
    ap.add_argument("out", type=Path)
    ap.add_argument("--subset", type=int, default=0, help="only the first N items per speaker")
    ap.add_argument("--split", default="", help="only this split (train, networks, dev or tune)")
    args = ap.parse_args()
    speakers = load_speakers(HERE / "config/corpus/real-speakers.txt")
    arpabet = load_map("arpabet")
    phones = {p.lower(): arpabet[p.lower()] for p in ARPABET}
    prons = None
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        (work / "ph.dict").write_text("".join(f"ph_{p.lower()} {p}\n" for p in ARPABET) +
                                      "sil SIL\n")
        for speaker, split, source in speakers:
            if args.split and split != args.split:
                continue
            folder = args.out / split / speaker
            folder.mkdir(parents=True, exist_ok=True)
            # Labels an older labeller wrote are made again (the WAVs are kept).
            stamp = folder / ".labeller"
            current = stamp.exists() and stamp.read_text().strip() == LABELLER_VERSION
            made = skipped = 0
            for name, audio, words, segments, text in items_of(args.root, source):
                if args.subset and made >= args.subset:
                    break
                wav, lab = folder / f"{name}.wav", folder / f"{name}.lab"
                if words == BY_ALIGNER and not wav.exists():
                    convert(audio, wav)
                if wav.exists() and ((lab.exists() and current) or words == BY_ALIGNER):
                    write_text(folder / f"{name}.txt", text)
                    made += 1
                    continue
                if words is not None:
                    if prons is None:
                        prons = load_dictionary()
                    spelled = spelling(words, prons)
                    if not spelled:
                        skipped += 1
                        continue
                duration = convert(audio, wav)
                if segments is None:
                    heard = labelling_audio(audio, wav, duration, work)
                    segments = trim_to_voice(align(heard, spelled, work, phones), heard)
                    if not any(s[2] != "sil" for s in segments):
                        wav.unlink()
                        lab.unlink(missing_ok=True)
                        skipped += 1
                        continue
                write_lab(lab, segments, duration)
                write_text(folder / f"{name}.txt", text)
                made += 1
            if not args.subset or made >= args.subset:  # every item this run asked for
                stamp.write_text(LABELLER_VERSION + "\n")
            log(f"{split}/{speaker}: {made} files ({skipped} skipped: words unknown or not aligned)")


if __name__ == "__main__":
    main()
