#!/usr/bin/env python3
"""What a frame classifier could hear from other inputs: the offline measurements behind the
docs/measurements.md's "Real people" tables on frame-classifier inputs (a development tool; needs python3-numpy).

    bench/frame-classifier-inputs.py [--real build/real-speech] [--corpus build/corpus/train]
                                     [--lipsync build/cli/lipsync] [--cache build/frame-inputs]
                                     [--seed 1] [--readers]

Every recording of the espeak-ng training corpus and of the real speakers
(config/corpus/real-speakers.txt, fetched by scripts/fetch-real-speech.sh) is analysed once with
`lipsync analyze --features` (the 34 features the front end decides on) and, for comparison, as a
24-band log mel filterbank to 5 kHz, and two cues of the waveform at the front end's 10 kHz (the
voicing as the highest normalised autocorrelation at 2.5–14 ms, Boersma 1993, and zero crossings
per ms); the frames are cached per speaker in --cache. A network of
the shipped class network's shape (32 rectified units, softmax, Adam, 4 passes, 256 frames a
batch) is trained on the espeak-ng corpus and the real training speakers other than the two that
are scored left out (klettres-en-gb, asterisk-en-allison), and scored per frame in visual groups
on those two and on the dev speakers. Choices are made on the left-out training speakers only.
Prints one line per input variant, then the vocal-tract-length warp upper bound. With --readers,
also the 34 features' network trained with more and more of the readers our aligner labelled for
the networks (train-templates.sh's build/real-speech/aligned/: the `networks` readers of
real-speakers.txt first, then any others there): how the figures grow with real speech.
"""
import argparse
import glob
import subprocess
import sys
import tempfile
import tomllib
import wave
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent.parent
LEFT_OUT = ["klettres-en-gb", "asterisk-en-allison"]


def phoneme_classes():
    doc = tomllib.loads((HERE / "config/phonemes/common.toml").read_text())
    table = next(v for v in doc.values() if isinstance(v, list))
    return [p["name"] for p in table], [p["group"] for p in table]


NAMES, GROUPS = phoneme_classes()
INDEX = {n: i for i, n in enumerate(NAMES)}
GROUP_OF = np.array([sorted(set(GROUPS)).index(g) for g in GROUPS])


def read_labels(lab):
    segments = []
    for line in lab.read_text().splitlines():
        f = line.split()
        try:
            segments.append((float(f[0]), float(f[1]), f[2]))
        except (IndexError, ValueError):
            continue
    return segments


def classes_at(times, segments):
    y = np.full(len(times), INDEX["sil"])
    for start, end, name in segments:
        y[(times >= start) & (times < end)] = INDEX.get(name, -1)  # -1: not scored
    return y


def lpc_frames(lipsync, wav, work):
    """(times, 34 features, gated silent) from `lipsync analyze --features`."""
    csv = work / "frames.csv"
    subprocess.run([lipsync, "analyze", str(wav), "-q", "-s", "/dev/null", "--features", str(csv)],
                   check=True)
    d = np.genfromtxt(csv, delimiter=",", skip_header=1, usecols=[0, 2] + list(range(4, 38)), ndmin=2)
    return d[:, 0], d[:, 2:].astype(np.float32), d[:, 1].astype(np.int8)


def mel_bank(rate, nfft, bands=24, low=100.0, high=5000.0):
    mel = lambda f: 2595 * np.log10(1 + f / 700)
    edges = 700 * (10 ** (np.linspace(mel(low), mel(high), bands + 2) / 2595) - 1)
    bins = np.fft.rfftfreq(nfft, 1 / rate)
    bank = np.zeros((bands, len(bins)))
    for i in range(bands):
        l, c, r = edges[i:i + 3]
        bank[i] = np.clip(np.minimum((bins - l) / (c - l), (r - bins) / (r - c)), 0, None)
    return bank


def mono(wav, dtype):
    """(rate, the file's samples in [-1, 1), its channels averaged) of a 16-bit WAV."""
    with wave.open(str(wav)) as w:
        rate, channels = w.getframerate(), w.getnchannels()
        x = np.frombuffer(w.readframes(w.getnframes()), dtype=np.int16).astype(dtype)
    return rate, x.reshape(-1, channels).mean(1) / 32768


def mel_frames(wav):
    """(times, 24 band levels in dB + the frame level relative to the file's loudest), 10 ms."""
    rate, x = mono(wav, np.float32)
    x = np.append(x[:1], x[1:] - 0.97 * x[:-1])
    hop, win = round(rate * 0.01), round(rate * 0.025)
    nfft = 1 << int(np.ceil(np.log2(win)))
    n = max(0, (len(x) - win) // hop + 1)
    frames = x[np.arange(win)[None, :] + hop * np.arange(n)[:, None]] * np.hamming(win)
    power = np.abs(np.fft.rfft(frames, nfft)) ** 2 @ mel_bank(rate, nfft).T
    bands = 10 * np.log10(power + 1e-10)
    level = 10 * np.log10(power.sum(1) + 1e-10)
    out = np.concatenate([bands - level[:, None], (level - level.max())[:, None]], axis=1)
    return (np.arange(n) * hop + win / 2) / rate, out.astype(np.float32)


def resampled(wav, rate_out=10000):
    """The file's mono samples at rate_out (band-limited by the FFT: dropped or zero bins)."""
    rate, x = mono(wav, np.float64)
    x -= x.mean()
    n = max(1, round(len(x) * rate_out / rate))
    spectrum = np.zeros(n // 2 + 1, complex)
    kept = np.fft.rfft(x)[:len(spectrum)]
    spectrum[:len(kept)] = kept
    return np.fft.irfft(spectrum, n) * n / max(1, len(x))


def waveform_cues(wav, times, rate=10000):
    """Per frame time: the voicing (Boersma 1993: the windowed frame's autocorrelation over the
    window's own, highest at lags 2.5–14 ms, over 40 ms) and zero crossings a ms (over 25 ms)."""
    x = resampled(wav, rate)
    win, half = round(rate * 0.04), round(rate * 0.02)
    padded = np.concatenate([np.zeros(half), x, np.zeros(half + 1)])
    at = np.clip(np.round(times * rate).astype(int), 0, len(x))
    frames = padded[at[:, None] + np.arange(win)[None, :]]
    frames -= frames.mean(1, keepdims=True)
    hann = np.hanning(win)
    nfft = 1 << int(np.ceil(np.log2(2 * win)))
    lags = slice(round(rate * 0.0025), round(rate * 0.014))
    ac = np.fft.irfft(np.abs(np.fft.rfft(frames * hann, nfft)) ** 2, nfft)
    own = np.fft.irfft(np.abs(np.fft.rfft(hann, nfft)) ** 2, nfft)
    voicing = (ac[:, lags] / (ac[:, :1] + 1e-12) / (own[lags] / own[0])).max(1)
    centre = frames[:, half - round(rate * 0.0125):half + round(rate * 0.0125)]
    crossings = (np.diff(np.signbit(centre).astype(np.int8), axis=1) != 0).sum(1) / 25.0
    return np.stack([np.clip(voicing, -1, 1), crossings], 1).astype(np.float32)


def speaker_frames(folder, lipsync, cache):
    """Cached per speaker: LPC features, mel features, classes, gate and file index per frame."""
    out = cache / f"{folder.parent.name}-{folder.name}.npz"
    if out.exists():
        data = dict(np.load(out))
        if "cues" in data:
            return data
    parts = {k: [] for k in ("lpc", "lpc_y", "gate", "lpc_file", "mel", "mel_y", "mel_file", "cues")}
    with tempfile.TemporaryDirectory() as tmp:
        for i, wav in enumerate(sorted(folder.glob("*.wav"))):
            lab = wav.with_suffix(".lab")
            if not lab.exists():
                continue
            segments = read_labels(lab)
            t, x, gate = lpc_frames(lipsync, wav, Path(tmp))
            parts["lpc"].append(x), parts["gate"].append(gate)
            parts["lpc_y"].append(classes_at(t, segments)), parts["lpc_file"].append(np.full(len(t), i))
            parts["cues"].append(waveform_cues(wav, t))
            t, x = mel_frames(wav)
            parts["mel"].append(x), parts["mel_y"].append(classes_at(t, segments))
            parts["mel_file"].append(np.full(len(t), i))
    data = {k: np.concatenate(v) for k, v in parts.items()}
    np.savez(out, **data)
    print(f"frame-classifier-inputs: {folder}: {len(data['lpc'])} frames", file=sys.stderr)
    return data


def neighbour(files, offset):
    """Per frame, the index of the frame `offset` away in the same file (else the frame itself)."""
    idx = np.arange(len(files))
    j = np.clip(idx + offset, 0, len(files) - 1)
    return np.where(files[j] == files, j, idx)


def slopes(x, files, reach=2):
    num = sum(k * (x[neighbour(files, k)] - x[neighbour(files, -k)]) for k in range(1, reach + 1))
    return num / (2 * sum(k * k for k in range(1, reach + 1)))


def causal_slopes(x, files, frames=4):
    """Each feature's least-squares slope over the frame and the `frames` before it, as
    `lipsync train --class-slopes` gives the class network (frames before a file's first: its first)."""
    first = np.zeros(len(files), dtype=int)
    starts = np.r_[0, np.flatnonzero(np.diff(files)) + 1]
    first[starts] = starts
    first = np.maximum.accumulate(first)
    weights = np.arange(frames + 1) - frames / 2
    idx = np.arange(len(files))
    return sum(w * x[np.maximum(idx - (frames - j), first)] for j, w in enumerate(weights)) / (weights ** 2).sum()


def variant_inputs(d, variant):
    x, f = d["lpc"], d["lpc_file"]
    if variant == "and their slopes over the last 5 frames":
        return np.concatenate([x, causal_slopes(x, f)], axis=1)
    if variant == "and their slopes (±2 frames)":
        return np.concatenate([x, slopes(x, f)], axis=1)
    if variant == "and their slopes and curvature":
        s = slopes(x, f)
        return np.concatenate([x, s, slopes(s, f)], axis=1)
    offsets = {"five frames, ±20 ms": [-2, -1, 0, 1, 2], "five frames, ±40 ms": [-4, -2, 0, 2, 4],
               "three frames, the last 40 ms": [-4, -2, 0]}[variant]
    return np.concatenate([x[neighbour(f, o)] for o in offsets], axis=1)


def train(inputs, classes, units=32, passes=4, seed=1):
    keep = classes >= 0
    x, y = inputs[keep], classes[keep]
    mean, scale = x.mean(0), 1 / (x.std(0) + 1e-6)
    x = (x - mean) * scale
    rng = np.random.default_rng(seed)
    n_in, n_out = x.shape[1], len(NAMES)
    params = [rng.standard_normal((n_in, units)).astype(np.float32) / np.sqrt(n_in),
              np.zeros(units, np.float32),
              rng.standard_normal((units, n_out)).astype(np.float32) / np.sqrt(units),
              np.zeros(n_out, np.float32)]
    m = [np.zeros_like(p) for p in params]
    v = [np.zeros_like(p) for p in params]
    step = 0
    for _ in range(passes):
        order = rng.permutation(len(x))
        for start in range(0, len(x), 256):
            b = order[start:start + 256]
            w1, b1, w2, b2 = params
            h = np.maximum(0, x[b] @ w1 + b1)
            z = h @ w2 + b2
            p = np.exp(z - z.max(1, keepdims=True))
            p /= p.sum(1, keepdims=True)
            p[np.arange(len(b)), y[b]] -= 1
            dz = p / len(b)
            dh = (dz @ w2.T) * (h > 0)
            grads = [x[b].T @ dh, dh.sum(0), h.T @ dz, dz.sum(0)]
            step += 1
            for i, g in enumerate(grads):  # Adam (Kingma & Ba 2015), as lipsync train
                m[i] = 0.9 * m[i] + 0.1 * g
                v[i] = 0.999 * v[i] + 0.001 * g * g
                params[i] -= 1e-3 * (m[i] / (1 - 0.9 ** step)) / (np.sqrt(v[i] / (1 - 0.999 ** step)) + 1e-8)
    return mean, scale, params


def log_posteriors(net, inputs):
    mean, scale, (w1, b1, w2, b2) = net
    z = np.maximum(0, ((inputs - mean) * scale) @ w1 + b1) @ w2 + b2
    return z - z.max(1, keepdims=True)


def group_accuracy(net, inputs, classes, gate=None, speech_only=False):
    guess = log_posteriors(net, inputs).argmax(1)
    if gate is not None:
        guess = np.where(gate == 1, INDEX["sil"], guess)  # the front end's energy gate
    scored = classes > 0 if speech_only else classes >= 0
    return 100 * (GROUP_OF[guess[scored]] == GROUP_OF[classes[scored]]).mean()


def mean_removed(d):
    """The mel bands less their file's mean over its speech (within 35 dB of its loudest)."""
    x = d["mel"].copy()
    for f in np.unique(d["mel_file"]):
        rows = d["mel_file"] == f
        speech = rows & (x[:, -1] > -35)
        x[rows, :-1] -= x[speech if speech.any() else rows, :-1].mean(0)
    return x


def warp(inputs, factor):
    """The 32-point spectrum read at `factor` times each bin's frequency (linear interpolation)."""
    src = np.clip(np.arange(32) * factor, 0, 31)
    lo = np.floor(src).astype(int)
    hi, frac = np.minimum(lo + 1, 31), src - lo
    spectrum = inputs[:, lo] * (1 - frac) + inputs[:, hi] * frac
    return np.concatenate([spectrum, inputs[:, 32:]], axis=1)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--real", type=Path, default=HERE / "build/real-speech")
    ap.add_argument("--corpus", type=Path, default=HERE / "build/corpus/train")
    ap.add_argument("--lipsync", default=str(HERE / "build/cli/lipsync"))
    ap.add_argument("--cache", type=Path, default=HERE / "build/frame-inputs")
    ap.add_argument("--seed", type=int, default=1, help="the networks' initial weights and batches")
    ap.add_argument("--readers", action="store_true", help="also train with more and more readers")
    args = ap.parse_args()
    args.cache.mkdir(parents=True, exist_ok=True)
    training, scored, readers = [], [], []
    for line in (HERE / "config/corpus/real-speakers.txt").read_text().splitlines():
        fields = line.split("#", 1)[0].split()
        if len(fields) == 3 and fields[1] == "networks":
            readers.append(args.real / "aligned" / fields[0])
        if len(fields) == 3 and (args.real / fields[1] / fields[0]).is_dir():
            speaker, split = fields[0], fields[1]
            if split == "networks":  # words only: their labels are the aligner's (train-templates.sh)
                continue
            # Only train speakers train (tune voices are held out like dev ones).
            (training if split == "train" and speaker not in LEFT_OUT else scored).append(
                args.real / split / speaker)
    training += [Path(p) for p in sorted(glob.glob(str(args.corpus / "*"))) if Path(p).is_dir()]
    if not scored:
        sys.exit(f"frame-classifier-inputs: no real speakers in {args.real} (scripts/fetch-real-speech.sh)")
    data = {f: speaker_frames(f, args.lipsync, args.cache) for f in training + scored}
    print("visual groups per frame: " + " / ".join(f.name for f in scored))

    def row(label, inputs_of, speech_only=False, gate=True, kind="lpc", more=()):
        net = train(np.concatenate([inputs_of(data[f]) for f in [*training, *more]]),
                    np.concatenate([data[f][f"{kind}_y"] for f in [*training, *more]]),
                    seed=args.seed)
        figures = [group_accuracy(net, inputs_of(data[f]), data[f][f"{kind}_y"],
                                  data[f]["gate"] if gate else None, speech_only) for f in scored]
        print(f"{label:45s}" + " / ".join(f"{a:.1f} %" for a in figures), flush=True)
        return net

    base = row("the 34 features", lambda d: d["lpc"])
    for variant in ["and their slopes (±2 frames)", "and their slopes and curvature",
                    "and their slopes over the last 5 frames",
                    "five frames, ±20 ms", "five frames, ±40 ms", "three frames, the last 40 ms"]:
        row(variant, lambda d, v=variant: variant_inputs(d, v))
    row("and the voicing and zero crossings", lambda d: np.concatenate([d["lpc"], d["cues"]], axis=1))
    print("speech frames only:")
    row("  the 34 LPC features", lambda d: d["lpc"], speech_only=True, gate=False)
    row("  24 log mel bands to 5 kHz and the level", lambda d: d["mel"], speech_only=True,
        gate=False, kind="mel")
    row("  the same, the file's mean bands removed", mean_removed, speech_only=True, gate=False,
        kind="mel")
    print("vocal-tract-length warp of the 34 features' network, best factor per speaker (an upper "
          "bound: chosen on the labels):")
    for f in scored:
        d = data[f]
        best = max((group_accuracy(base, warp(d["lpc"], a), d["lpc_y"], d["gate"]), a)
                   for a in np.arange(0.84, 1.17, 0.04))
        print(f"  {f.name}: {best[0]:.1f} % at {best[1]:.2f}")
    if args.readers:
        others = sorted(p for p in (args.real / "aligned").glob("*") if p.is_dir() and p not in readers)
        readers = [r for r in readers if r.is_dir()] + others
        data.update({f: speaker_frames(f, args.lipsync, args.cache) for f in readers})
        print("the 34 features, more readers in training (real frames: the readers' and the train speakers'):")
        for k in sorted({0, min(2, len(readers)), len(readers) - len(others), len(readers)}):
            frames = sum(len(data[f]["lpc"]) for f in [*training, *readers[:k]] if args.real in f.parents)
            row(f"  {k} readers ({frames} frames)", lambda d: d["lpc"], more=readers[:k])
            if k == len(readers) - len(others):  # the shipped networks' readers
                row("  and their slopes over the last 5 frames",
                    lambda d: variant_inputs(d, "and their slopes over the last 5 frames"),
                    more=readers[:k])


if __name__ == "__main__":
    main()
