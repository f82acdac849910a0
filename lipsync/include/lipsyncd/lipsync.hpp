// lipsync: phoneme schedule in, mouth-pose weights out, by the phone-bigram method
// (shared/seeds/000, section 2.2).
//
//   PoseSet          the canonical mouth poses (config/poses/*.toml): per pose a priority, a
//                    speed limit and a smoothing window; per pose pair a constraint threshold.
//   ControlCurve     a piecewise-linear control polygon over normalised time [0, 1] and the
//                    smooth uniform cubic B-spline it controls (what the runtime evaluates).
//   BigramCurveSet   per phone bigram and pose, a ControlCurve (config/curves/*.json); a
//                    character file overrides single bigrams of a base set.
//   generateCurveSet the shipped English set from per-class targets and coarticulation rules.
//   animate()        the runtime, offline: pairs → time-warp → stitch with max → valley
//                    smoothing → constraints → speed limits, each step switchable.
//   StreamingRuntime the same, fed segment by segment, with a fixed delay (or causal).
//   animateFilter()  the viseme-space filter of paper 001, section 5: a second, simpler runtime.
//   RuntimeSpec      the runtime as a user names it (pose set, curves or character, phoneme
//                    set, kind, steps); `lipsync`'s options and lipsyncd's [mouth] fill it.
//   Runtime          a RuntimeSpec loaded once: the one place both build the runtime from.
//                    Where the audio is known it also blends in the heard jaw (blendHeardJaw),
//                    shapes by loudness (shapeByLoudness) and, from the audio alone, deepens
//                    the jaw's dips between syllables (deepenDips).
#pragma once

#include <cstddef>
#include <filesystem>
#include <lipsyncd/core.hpp>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace lipsyncd::lipsync {

// ---------------------------------------------------------------------------------------------
// Poses.

struct Pose {
    std::string name;
    int priority = 0;               // on a constraint, the lower-priority pose gives way
    double speedLimit = 6.0;        // weight units per second (section 2.2.3)
    double smoothingWindow = 0.18;  // 2·t_w, seconds (section 2.2.1)
    // How much of the pose's weight speech loudness controls (shapeByLoudness): 0 none, 1 all.
    double loudnessGain = 0;
    // How much of the weight the jaw heard in the audio sets (blendHeardJaw): 0 none, 1 all;
    // for speech aligned on its words (LevelTrack::aligned), heardJawAligned.
    double heardJaw = 0;
    double heardJawAligned = 0;
    // A pose (the lips' closure) whose weight w holds the heard jaw back to (1 − w) of its share:
    // a closure the schedule places stays closed. Empty: none.
    std::string heardJawClosedBy;
    // Offline, on speech analysed from audio alone, that closure is doubted where the heard jaw
    // is open: it holds the heard jaw back fully below closureHeldBelow, not at all above
    // closureDoubtedAbove, and in between in proportion. Above 1 both: never doubted.
    double closureHeldBelow = 2;
    double closureDoubtedAbove = 2;
    // Offline, on speech analysed from audio alone: a clear dip (the weight rising by dipRise
    // on both sides) is lowered by dipDepth at its lowest point (deepenDips). 0: none.
    double dipDepth = 0;
    double dipRise = 0.05;
};

// The mouth rests when speech stops: from the start of a silence at least `minPause` long (and
// at the end of a schedule) every pose is at 0 within `within` seconds, and stays there until
// `within` before the next phoneme starts (restInPauses).
struct RestRule {
    double minPause = 0.25;
    double within = 0.12;
};

// C(a, b): when c_a + c_b > threshold, the lower-priority of the two is reduced (2.2.2).
struct PoseConstraint {
    std::size_t high = 0, low = 0;  // pose indices, priority(high) > priority(low)
    double threshold = 2.0;
};

class PoseSet {
  public:
    static PoseSet load(const std::filesystem::path& file);  // validates; InputError
    static PoseSet named(const std::string& nameOrPath);  // "facefx" → config/poses/facefx.toml

    const std::string& name() const { return name_; }
    std::size_t size() const { return poses_.size(); }
    const Pose& operator[](std::size_t i) const { return poses_[i]; }
    std::span<const Pose> poses() const { return poses_; }
    std::vector<std::string> names() const;
    std::optional<std::size_t> find(const std::string& name) const;
    // In the order they are applied: by the higher pose's priority, highest first.
    std::span<const PoseConstraint> constraints() const { return constraints_; }
    const RestRule& rest() const { return rest_; }

    PoseSet(std::string name, std::vector<Pose> poses, std::vector<PoseConstraint> constraints,
            RestRule rest = {});

  private:
    std::string name_;
    std::vector<Pose> poses_;
    std::vector<PoseConstraint> constraints_;
    RestRule rest_;
};

// ---------------------------------------------------------------------------------------------
// Curves.

struct ControlPoint {
    float time = 0;   // normalised, in [0, 1]
    float value = 0;  // pose weight, in [0, 1]
    bool operator==(const ControlPoint&) const = default;
};

// The paper's curve l(t) is the control polygon of a smooth B-spline c(t). The polygon's
// vertices are the control points of a clamped uniform cubic B-spline in the (time, value)
// plane; it starts and ends on the polygon's end points and stays inside its convex hull, so
// values stay in [0, 1]. It is sampled densely once, at load time.
class ControlCurve {
  public:
    explicit ControlCurve(std::vector<ControlPoint> polygon);  // validated by the caller
    float at(double u) const;                                  // u in [0, 1], clamped
    std::span<const ControlPoint> polygon() const { return polygon_; }

  private:
    std::vector<ControlPoint> polygon_;
    std::vector<float> samples_;  // c(u) at u = i / (samples_.size() - 1)
};

class BigramCurveSet {
  public:
    // A curve set (format "lipsyncd-curves") or a character file ("lipsyncd-character": a base
    // set plus overridden bigrams). Validates everything; errors name the bigram and pose.
    static BigramCurveSet load(const std::filesystem::path& file, const PoseSet& poses,
                               const PhonemeSet& phonemes = PhonemeSet::common());
    static BigramCurveSet named(const std::string& nameOrPath, const PoseSet& poses,
                                const PhonemeSet& phonemes = PhonemeSet::common());
    // An empty set (every curve zero) over these classes and poses: the generator fills it.
    BigramCurveSet(std::string name, const PoseSet& poses, const PhonemeSet& phonemes);

    // The curve of `pose` for the bigram (first, second), or nullptr when the pose stays at 0.
    const ControlCurve* curve(std::size_t first, std::size_t second, std::size_t pose) const;
    void setCurve(std::size_t first, std::size_t second, std::size_t pose, ControlCurve curve);
    // Applies a character file's bigrams on top of this set.
    void applyOverrides(const std::filesystem::path& characterFile, const PoseSet& poses,
                        const PhonemeSet& phonemes = PhonemeSet::common());
    // The same for bigrams already in memory, as JSON text in a character file's "bigrams"
    // form ({"a-b": {pose: [[t, v], ...]}}), checked as load() checks a file; errors name
    // `source` where load() names the file (the curve editor's requests). On an error some
    // of the bigrams may be applied already: apply to a scratch set, then copy.
    void applyBigramsJson(std::string_view bigramsJson, const std::string& source,
                          const PoseSet& poses, const PhonemeSet& phonemes = PhonemeSet::common());

    const std::string& name() const { return name_; }
    std::string& description() { return description_; }
    std::size_t classes() const { return classes_; }
    std::size_t poses() const { return poses_; }
    // Writes the set (format "lipsyncd-curves", version 1), deterministically.
    void save(const std::filesystem::path& file, const PoseSet& poseSet,
              const PhonemeSet& set) const;
    // Writes only the bigrams that involve class `onlyWith`, as a character file on `base`
    // (a language's additions to a set: paper 000, section 4.4).
    void saveAdditions(const std::filesystem::path& file, const std::string& base,
                       std::size_t onlyWith, const PoseSet& poseSet, const PhonemeSet& set) const;

  private:
    static BigramCurveSet loadSet(const std::filesystem::path& file, const PoseSet& poses,
                                  const PhonemeSet& phonemes, bool requireEveryPair);
    void requireEveryPair(const std::filesystem::path& file, const PhonemeSet& phonemes) const;
    std::size_t slot(std::size_t first, std::size_t second, std::size_t pose) const {
        return (first * classes_ + second) * poses_ + pose;
    }
    std::string name_, description_;
    std::size_t classes_ = 0, poses_ = 0;
    std::vector<std::optional<ControlCurve>> curves_;
    std::vector<bool> defined_;  // per bigram: listed in a file (or set by the generator)
};

// The shipped English set: per-class target poses and coarticulation rules, from a rules file
// (config/curves/english-rules.toml; format documented in config/curves/README.md).
BigramCurveSet generateCurveSet(const std::filesystem::path& rulesFile, const PoseSet& poses,
                                const PhonemeSet& phonemes = PhonemeSet::common());

// ---------------------------------------------------------------------------------------------
// The runtime.

struct RuntimeConfig {
    double outputRate = 100;  // weight frames per second
    // Each step of section 2.2 after the stitch can be switched off, for comparison.
    bool smoothing = true;
    bool constraints = true;
    bool speedLimits = true;
    bool restInPauses = true;
};

// Pose weights over time, one row of `poses` values per output frame: the runtime's working
// form (pose-major, so each step runs down one curve at a time).
struct PoseCurves {
    double startTime = 0;        // time of global frame 0
    std::size_t firstFrame = 0;  // global index of values[p][0] (streaming works on a window)
    double rate = 100;
    std::size_t frames = 0;
    std::vector<std::vector<float>> values;  // [pose][frame]

    PoseCurves(std::size_t poses, double rate, double startTime, std::size_t firstFrame,
               std::size_t frames);
    double timeOf(std::size_t frame) const {
        return startTime + static_cast<double>(firstFrame + frame) / rate;
    }
};

// The steps, in the paper's order (each in its own file, each with its own tests).
// Pairs (p_i, p_i+1) over (t_i, t_i+2), curves warped onto that span (each phoneme's half of
// normalised time onto that phoneme), overlaps stitched with max (2.2.1). The schedule is bracketed
// by zero-length silence (where it starts and ends, unless told it continues), so the first and
// last phonemes are covered by a pair too.
struct Bracket {
    bool start = true, end = true;
};
void stitchBigrams(std::span<const PhonemeSegment> schedule, const BigramCurveSet& set,
                   const PhonemeSet& phonemes, PoseCurves& curves, Bracket bracket = {});
// Valleys between two local maxima less than the pose's window apart are filled by the line
// between the maxima (2.2.1).
void smoothValleys(std::span<float> curve, double rate, double window);
// c_a + c_b ≤ C(a, b): the lower-priority pose gives way (2.2.2).
void applyConstraints(const PoseSet& poses, PoseCurves& curves, std::size_t fromFrame = 0);
// |dc/dt| ≤ the pose's limit, frame by frame from `previous` (the last frame already out);
// never re-breaks a constraint (2.2.3).
void limitSpeed(const PoseSet& poses, bool keepConstraints, std::span<const float> previous,
                PoseCurves& curves, std::size_t fromFrame = 0);
// What limitSpeed works in, for a caller that runs it every tick (the streaming runtime): kept
// between calls, so a call allocates nothing. Built for one pose set.
struct SpeedLimitScratch {
    explicit SpeedLimitScratch(const PoseSet& poses);
    std::vector<std::size_t> order;  // the poses as placed: highest priority first
    std::vector<float> prev, now;    // one frame each
};
void limitSpeed(const PoseSet& poses, bool keepConstraints, std::span<const float> previous,
                PoseCurves& curves, std::size_t fromFrame, SpeedLimitScratch& scratch);

// Silences at least rest.minPause long, and a silence that opens or closes the schedule (where
// `bracket` says it starts or ends there): every pose is scaled by a ramp that reaches 0
// `within` after the silence starts and leaves 0 `within` before it ends, so the mouth rests in
// pauses and after speech whatever the curves hold. Runs after the constraints (it only lowers
// weights) and before the speed limits, which then smooth it.
void restInPauses(std::span<const PhonemeSegment> schedule, const PhonemeSet& phonemes,
                  const RestRule& rest, PoseCurves& curves, std::size_t fromFrame = 0,
                  Bracket bracket = {});

// Louder speech opens wider, within the opening a phoneme allows (Lewis 1991 reports each
// frame's excitation volume for this). A pose with loudness gain g is scaled by
// 1 − g + g·s, where s in [0, 1] is the frame's level relative to the utterance's speaking
// level L (0 at L − rangeDb, 1 at L and above). It only ever lowers a weight, so a closure (a
// nasal m, a bilabial) stays closed however loud it is, and rest stays rest.
struct LoudnessConfig {
    double rangeDb = 18;            // from "quiet" (s = 0) to the speaking level (s = 1)
    double percentile = 0.9;        // offline: L is this percentile of the speech frames' levels
    double speechBelowPeakDb = 40;  // frames this far below the loudest are not speech
    double peakDecayDbPerS = 3;     // streaming: L is a peak that decays this fast
    // Offline: speech within fadeHoldSeconds of a pause is shaped by the level at least as loud
    // as fadeHoldSeconds before the pause. A word's sound fades while the mouth still holds its
    // last phoneme, and the rest ramp (restInPauses) closes it once the pause starts; read as
    // quieter speech, the fade had shut the mouth early. Chosen on the tune voices
    // (docs/measurements.md, "Where the jaw's opening is lost, by phoneme"): 0.05 / 0.08 / 0.1 /
    // 0.12 / 0.15 / 0.2 s gave false closures 50.7 → 49.3 / 48.9 / 48.9 / 48.9 / 48.9 / 48.9
    // summed, jaw r 3.902 → 3.906 / 3.908 / 3.908 / 3.908 / 3.907 / 3.904, closures caught 355.2
    // → 355.1 up to 0.1 s, then falling (351.8 at 0.2 s); 0: none. The live stream cannot know a
    // pause is coming, and does not hold.
    double fadeHoldSeconds = 0.1;
};
// Offline: L from the whole utterance. `levels` are frame RMS in dBFS (dsp::measureLevels);
// `schedule` (the phonemes the track was made from) says where silences start.
void shapeByLoudness(const PoseSet& poses, const LevelTrack& levels,
                     std::span<const PhonemeSegment> schedule, const PhonemeSet& phonemes,
                     PoseTrack& track, const LoudnessConfig& config = {});
// A syllable closes the jaw: each clear dip of a pose with a dip_depth (its lowest point within
// ±lowestWithin, the weight rising by the pose's dip_rise within riseWithin on both sides) is
// lowered by dip_depth at its lowest frame, tapering to nothing at ±(taper + one frame).
// Offline only (riseWithin of lookahead). The runtime runs it on speech analysed from audio
// alone, whose jaw the heard jaw's smoothing sets; aligned speech's curves dip at its known
// consonants, and a deeper dip there only cost jaw r and false closures (measured).
struct DipConfig {
    double lowestWithin = 0.03;
    double riseWithin = 0.06;
    double taper = 0.01;
};
void deepenDips(const PoseSet& poses, PoseTrack& track, const DipConfig& config = {});
// The jaw the front end heard (LevelTrack::jaw: per frame, the jaw height its class scores point
// to, smoothed over `smoothingSeconds`) blended into each pose with a heard_jaw share g:
// w' = (1 − g)·w + g·heard (g: heard_jaw, or heard_jaw_aligned for a track of aligned speech).
// Nothing where the track has no jaw (phonemes known exactly: say).
// The window the heard jaw is averaged over, offline and in the live stream alike.
inline constexpr double kHeardJawSmoothingSeconds = 0.04;
void blendHeardJaw(const PoseSet& poses, const LevelTrack& levels, PoseTrack& track,
                   double smoothingSeconds = kHeardJawSmoothingSeconds);
// What the heard jaw is blended into: speech analysed offline from audio alone (the
// schedule's closures doubted where the heard jaw is open, as the dips of deepenDips close the
// jaw instead), speech aligned on its words (heard_jaw_aligned), or a live stream (heard_jaw,
// every closure the schedule places kept: it has no dips to close the jaw).
enum class HeardSpeech { analysed, aligned, live };
// One frame of weights (poses in pose-set order) and the jaw heard around its time: what the
// offline blend does per frame, for a live stream (the service's live mode).
void blendHeardJaw(const PoseSet& poses, double heard, std::span<float> weights,
                   HeardSpeech speech = HeardSpeech::live);

// Streaming: L is a decaying peak of the levels seen so far; frames are shaped as they leave.
class LoudnessShaper {
  public:
    LoudnessShaper(const PoseSet& poses, const LoudnessConfig& config = {});
    // Shapes one frame of weights (poses in pose-set order) at a level of `db`, `dt` seconds
    // after the previous call.
    void shape(float db, double dt, std::span<float> weights);

  private:
    std::vector<double> gains_;
    LoudnessConfig config_;
    double peak_ = -120;
};

// The whole runtime over a schedule (contiguous, common-set names).
PoseTrack animate(std::span<const PhonemeSegment> schedule, const BigramCurveSet& set,
                  const PoseSet& poses, const RuntimeConfig& config = {},
                  const PhonemeSet& phonemes = PhonemeSet::common());

// The viseme-space filter of paper 001, section 5 (`--runtime filter`): per 10 ms slot the
// pose vector of its phoneme, filtered a'_i = 0.1·a_i−1 + 0.5·a_i + 0.3·a_i+1 + 0.1·a_i+3 and
// averaged down to the output rate. Each class's pose vector is what the curve set holds for
// it (its self-bigram at the first phoneme's centre). Looks only 30 ms ahead.
PoseTrack animateFilter(std::span<const PhonemeSegment> schedule, const BigramCurveSet& set,
                        const PoseSet& poses, const RuntimeConfig& config = {},
                        const PhonemeSet& phonemes = PhonemeSet::common());

// Streaming: segments arrive as the front end closes them; weights leave with a fixed delay.
// A frame at time t goes out once segments are closed up to t + delay. With a delay longer
// than two segments plus the smoothing window, the output equals animate()'s exactly.
// delay = 0 is the causal mode: the next phoneme is unknown, so frames up to the last closed
// boundary are computed against an estimate (the current phoneme continued, for its mean
// duration so far) and go out at once.
// It runs on the live path (a push or preview every 10 ms): its work and memory per call are
// bounded by the smoothing window and the delay, not by how long a phoneme or a pause lasts,
// and preview() and push() allocate nothing (a push that lets out more than a few seconds at
// once, after a long segment with a delay, grows its buffers once).
class StreamingRuntime {
  public:
    StreamingRuntime(const BigramCurveSet& set, const PoseSet& poses, double delaySeconds,
                     const RuntimeConfig& config = {},
                     const PhonemeSet& phonemes = PhonemeSet::common());
    // Appends the frames that became final to `out` (out.poses must be the pose names).
    void push(const PhonemeSegment& segment, PoseTrack& out);
    void finish(PoseTrack& out);
    // Causal mode only: the phoneme still being spoken (not yet closed) is `phoneme` up to
    // `until`; frames up to `until` go out now, warped as if it lasts as long as the phonemes
    // so far on average. When it closes, push() carries on from there with the truth.
    void preview(const std::string& phoneme, double until, PoseTrack& out);
    // Causal mode only, before a push() or preview(): what is expected to come next, from
    // `from` on (a followed line's words say it). The guess of what follows the newest phoneme
    // takes it, instead of that phoneme going on; it holds for that one call.
    void expect(const std::string& phoneme, double from);
    double delaySeconds() const { return delay_; }

  private:
    void emitUntil(double until, bool final, PoseTrack& out, const PhonemeSegment* open = nullptr);
    void buildSchedule(bool causal, const PhonemeSegment* open);
    void resetCurves(std::size_t firstFrame, std::size_t frames);
    void dropOldSegments();
    double pastKept() const;
    double longestWindow() const;

    const BigramCurveSet* set_;
    const PoseSet* poses_;
    const PhonemeSet* phonemes_;
    RuntimeConfig config_;
    double delay_;
    std::vector<PhonemeSegment> window_;  // recent segments (older ones are dropped)
    bool started_ = false;
    bool atStart_ = true;      // window_ still holds the first segment
    double origin_ = 0;        // time of frame 0: the first segment's start
    std::size_t emitted_ = 0;  // frames already out
    std::vector<float> last_;  // the last frame out
    // Each emitUntil's working state, kept so that it reuses their memory instead of allocating.
    std::vector<PhonemeSegment> schedule_;  // window_, plus the causal mode's estimate
    std::optional<PhonemeSegment> expected_;  // expect(): for the next push or preview only
    PoseCurves curves_;
    SpeedLimitScratch speed_;
};

// ---------------------------------------------------------------------------------------------
// The runtime by name: what `lipsync animate/analyze/align/say/eval` and lipsyncd's [mouth]
// table both say, built in one place so the two never drift apart.

struct RuntimeSpec {
    std::string poses = "facefx";     // config/poses/NAME.toml or a file
    std::string curves = "english";   // config/curves/NAME.json or a file
    std::string character;            // a character file (a base set, some bigrams replaced)
    std::string phonemes = "common";  // config/phonemes/NAME.toml or a file: the schedule's set
    std::string kind = "bigram";      // bigram (paper 000) | filter (paper 001, section 5)
    RuntimeConfig config;
    bool loudness = true;  // louder speech opens wider (the poses' loudness_gain)
    bool heardJaw = true;  // the jaw heard in the audio sets part of it (the poses' heard_jaw)
};

class Runtime {
  public:
    // Loads the pose set, the phoneme set and the curves (or the character). InputError
    // naming the spec's field, the value and the file ("curves 'x': FILE:LINE: ...").
    explicit Runtime(RuntimeSpec spec);
    // Streaming runtimes point into it: it stays where it was built.
    Runtime(const Runtime&) = delete;
    Runtime& operator=(const Runtime&) = delete;

    const RuntimeSpec& spec() const { return spec_; }
    const PoseSet& poses() const { return poses_; }
    const PhonemeSet& phonemes() const { return *phonemes_; }
    const BigramCurveSet& curves() const { return curves_; }

    // Offline, the spec's kind; with `levels` (the speech's frame levels) and spec.loudness,
    // louder speech opens wider within what each phoneme allows; with their jaw track (audio
    // analysed by the front end) and spec.heardJaw, the heard jaw is blended in first.
    PoseTrack animate(std::span<const PhonemeSegment> schedule,
                      const LevelTrack* levels = nullptr) const;
    // Segment by segment (the bigram runtime) with `delaySeconds` of look-ahead, 0: causal.
    StreamingRuntime streaming(double delaySeconds) const;

  private:
    RuntimeSpec spec_;
    const PhonemeSet* phonemes_;
    PoseSet poses_;
    BigramCurveSet curves_;
};

// ---------------------------------------------------------------------------------------------
// Scoring a jaw.

// How a puppet's jaw is judged against reference labels (`lipsync eval`). Jaw values are
// normalised to the jaw's travel: 0 closed, 1 fully open.
struct JawScoreConfig {
    double smoothingSeconds = 0.04;      // the reference: each phoneme's jaw height, moving average
    double closedBelow = 0.15;           // a jaw below this shows a closed mouth
    double clearlyOpenAbove = 0.5;       // a reference above this is a clearly open mouth
    double closureMarginSeconds = 0.03;  // a closure counts if the jaw closes within its ± this
};

// The reference jaw: frame f (at f / rate seconds) holds the jaw height of the phoneme labelled
// there (PhonemeClass::jaw), smoothed by a centred moving average. InputError for a set without
// jaw heights.
std::vector<float> jawReference(std::span<const PhonemeSegment> labels, const PhonemeSet& set,
                                double rate, std::size_t frames, const JawScoreConfig& config = {});

struct JawScore {
    // Sums for Pearson's r over every frame scored (so scores of files add up to a speaker's).
    double n = 0, sx = 0, sy = 0, sxx = 0, syy = 0, sxy = 0;
    // Closures inside speech (a "closed"-group phoneme between two non-silent ones) and how many
    // of them the jaw showed; frames where the reference is clearly open and how many of them
    // the jaw showed closed.
    std::size_t closures = 0, closuresCaught = 0, openFrames = 0, falseClosures = 0;
    double openJaw = 0;  // the jaw summed over the clearly open frames
    // Per class of the phoneme set (by index), over the frames labelled as it: the jaw summed
    // and the frames. Empty until a frame is scored.
    std::vector<double> classJaw;
    std::vector<std::size_t> classFrames;

    // How far the jaw opens, on average, where the reference is clearly open (0..1 of its
    // travel): r cannot see a mouth that moves at the right times but too little.
    double openingWhereOpen() const { return openFrames ? openJaw / double(openFrames) : 0.0; }
    // The mean jaw over the frames labelled as class `c` (0 without any): which phonemes the
    // opening is lost on.
    double meanJawOf(std::size_t c) const {
        return c < classFrames.size() && classFrames[c] ? classJaw[c] / double(classFrames[c])
                                                        : 0.0;
    }

    double r() const;  // Pearson correlation of jaw and reference; 0 when either is constant
    double closureRate() const { return closures ? double(closuresCaught) / closures : 1.0; }
    double falseClosureRate() const {
        return openFrames ? double(falseClosures) / openFrames : 0.0;
    }
    void add(const JawScore& other);
};
JawScore scoreJaw(std::span<const float> jaw, std::span<const float> reference,
                  std::span<const PhonemeSegment> labels, const PhonemeSet& set, double rate,
                  const JawScoreConfig& config = {});

}  // namespace lipsyncd::lipsync
