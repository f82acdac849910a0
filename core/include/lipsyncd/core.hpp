// lipsyncd core: the data every stage passes on.
//
//   PhonemeSet      the classes a schedule speaks in (the Common Phoneme Set of paper 000,
//                   table 1, plus silence), with the coarse visual group of each class.
//   PhonemeMap      how another alphabet (ARPAbet, espeak-ng mnemonics, IPA, pinyin) maps onto
//                   the set.
//   PhonemeSchedule timed segments (start, end, phoneme, confidence): the output of the front
//                   end and the input of the runtime; read and written as TSV (DESIGN.md).
//   PoseTrack       pose weights over time (one value per pose per output frame): the output of
//                   the runtime and the input of the actuator stage; CSV `time,<pose>,...`.
//   InputError      what every loader throws: a message that names the file, line and field.
//
// All of these are plain values, loaded from files under config/ and validated on load.
#pragma once

#include <cstddef>
#include <filesystem>
#include <iosfwd>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

namespace lipsyncd {

// An error in something the user gave us (a file, an option, a request). The message reads
// "FILE:LINE: what is wrong" (line omitted where there is none) so editors can jump to it.
class InputError : public std::runtime_error {
  public:
    InputError(const std::string& file, std::size_t line, const std::string& what);
    explicit InputError(const std::string& what) : std::runtime_error(what) {}
};

// Where shipped data lives: $LIPSYNCD_DATA_DIR if set, the installed share/lipsyncd when the
// running binary is installed, else the source tree's config/ (so a fresh build just works).
std::filesystem::path dataDirectory();
// `name` as given if it exists, else resolved against dataDirectory().
std::filesystem::path findDataFile(const std::filesystem::path& name);
// A shipped data file named the short way ("facefx" → config/poses/facefx.toml) or by path
// (anything with an extension or a folder in it).
std::filesystem::path findNamedDataFile(const std::string& nameOrPath,
                                        const std::filesystem::path& folder,
                                        const std::string& extension);

// ---------------------------------------------------------------------------------------------
// Phoneme classes.

struct PhonemeClass {
    std::string name;      // "aa", "bmp", "sil", ...
    std::string group;     // coarse visual group: silence, open, mid, rounded, closed, ...
    std::string examples;  // words that show it, for people reading a report
    bool vowel = false;
    // How far the jaw opens for this class in running speech, 0 (closed, as at a bilabial
    // closure) to 1 (the widest opening of speech): the puppet's jaw target and the reference
    // `lipsync eval` scores a jaw against. Sources in config/phonemes/common.toml.
    std::optional<float> jaw;
};

class PhonemeSet {
  public:
    // A set file may say `extends = "common"`: its classes come after the base set's (a
    // language adds the phonemes the common set lacks, as paper 000, section 4.4 adds one).
    static PhonemeSet load(const std::filesystem::path& file);
    // "common", "mandarin" (config/phonemes/NAME.toml) or a path; loaded once per name.
    static const PhonemeSet& named(const std::string& nameOrPath);
    // The shipped Common Phoneme Set (config/phonemes/common.toml).
    static const PhonemeSet& common();

    std::size_t size() const { return classes_.size(); }
    const PhonemeClass& operator[](std::size_t i) const { return classes_[i]; }
    std::span<const PhonemeClass> classes() const { return classes_; }
    std::optional<std::size_t> find(std::string_view name) const;
    // Index of the silence class ("sil"); every set has one.
    std::size_t silence() const { return silence_; }
    // The visual groups in first-seen order, for reports.
    std::vector<std::string> groups() const;

    explicit PhonemeSet(std::vector<PhonemeClass> classes);  // validates; throws InputError

  private:
    std::vector<PhonemeClass> classes_;
    std::unordered_map<std::string, std::size_t> index_;
    std::size_t silence_ = 0;
};

// Maps symbols of one alphabet onto class names of a PhonemeSet.
class PhonemeMap {
  public:
    struct Result {
        std::string phoneme;  // a class name of the set
        bool approximate;     // from the map's [nearest] table: the caller should warn
    };
    // `fallback = "NAME"`: symbols this map lacks are looked up in that map (config/phonemes/).
    static PhonemeMap load(const std::filesystem::path& file);
    // Loads config/phonemes/<name>.toml (or a path).
    static PhonemeMap named(std::string_view nameOrPath);

    // nullopt for a symbol the map does not know (callers warn, naming it).
    std::optional<Result> map(std::string_view symbol) const;
    // Marks that are not sounds at all (stress, syllable breaks, and in any map a name in
    // parentheses, espeak-ng's switch of language): callers skip them silently.
    bool isIgnored(std::string_view symbol) const;
    const std::string& name() const { return name_; }
    // The phoneme set the map's targets belong to (its `phoneme_set` key; "common" if absent).
    const std::string& phonemeSet() const { return phonemeSet_; }

  private:
    static PhonemeMap load(const std::filesystem::path& file, int depth);
    void addFallback(const std::filesystem::path& file, const std::string& name, int depth);
    std::string normalise(std::string_view symbol) const;
    std::string name_;
    std::string phonemeSet_ = "common";
    bool caseSensitive_ = true;
    bool stripStressDigits_ = false;
    std::unordered_map<std::string, std::string> exact_;
    std::unordered_map<std::string, std::string> nearest_;
    std::vector<std::string> ignored_;
};

// ---------------------------------------------------------------------------------------------
// Schedules.

struct PhonemeSegment {
    double start = 0;  // seconds
    double end = 0;    // seconds
    std::string phoneme;
    float confidence = 1.0f;  // in [0, 1]; 1 for labels and TTS

    double duration() const { return end - start; }
    bool operator==(const PhonemeSegment&) const = default;
};

using PhonemeSchedule = std::vector<PhonemeSegment>;

struct ScheduleReadOptions {
    // Translate symbols through this map (e.g. ARPAbet labels); nullptr: names must already be
    // classes of `set`, though a map can still be guessed per symbol (see readSchedule).
    const PhonemeMap* map = nullptr;
    const PhonemeSet* set = nullptr;  // nullptr: PhonemeSet::common()
    // Gaps between segments become silence (labels often omit pauses); otherwise an error.
    bool fillGapsWithSilence = true;
    // Symbols nobody knows: warn (naming symbol and line) and treat as silence, or fail.
    bool unknownIsError = false;
};

// Reads TSV / .lab text: `start end phoneme [confidence]` separated by tabs or spaces, '#'
// comments and blank lines allowed. Checks times (finite, within 0 .. 86400 s, end > start,
// sorted, no overlaps) and phonemes; errors name `sourceName` and the line. Warnings go to
// `warnings`.
PhonemeSchedule readSchedule(std::istream& in, const std::string& sourceName,
                             const ScheduleReadOptions& options = {},
                             std::vector<std::string>* warnings = nullptr);
PhonemeSchedule readScheduleFile(const std::filesystem::path& file,
                                 const ScheduleReadOptions& options = {},
                                 std::vector<std::string>* warnings = nullptr);

// Writes TSV, times with millisecond precision; confidence column when `withConfidence`.
void writeSchedule(std::ostream& out, std::span<const PhonemeSegment> schedule,
                   bool withConfidence = true);
// JSON array of {"start","end","phoneme","confidence"}.
void writeScheduleJson(std::ostream& out, std::span<const PhonemeSegment> schedule);

// ---------------------------------------------------------------------------------------------
// Loudness.

// The speech level over time, one value per analysis frame (frame f is at start + f / rate):
// what Lewis's analysis reports as each frame's excitation volume, used to let louder speech
// open the mouth wider (lipsync::shapeByLoudness).
struct LevelTrack {
    double start = 0;       // seconds: time of frame 0
    double rate = 100;      // frames per second
    std::vector<float> db;  // frame RMS in dBFS
    // Per frame (the same frames), when the audio went through the front end: the jaw height its
    // class scores point to (dsp FrameLabel::jaw), which the runtime can blend into the jaw
    // pose (lipsync::blendHeardJaw). Empty otherwise (speech whose phonemes are known).
    std::vector<float> jaw;
    // The schedule beside this track was aligned on known words (dsp alignText): its phonemes
    // are surer than audio-only analysis's, so the heard jaw takes the smaller share a pose set
    // gives aligned speech (heard_jaw_aligned).
    bool aligned = false;
    // The level at time t (nearest frame; the first/last frame outside the track).
    float at(double t) const;
    // Appends the next frame's level; the first frame's time sets `start`.
    void add(double time, float frameDb);
    // The utterance's speaking level: the `percentile` of the frames within `belowPeakDb` of
    // the loudest, so a single shout or click does not set it; -120 for an empty track.
    float speakingLevel(double percentile, double belowPeakDb) const;
};

// ---------------------------------------------------------------------------------------------
// Pose weights.

struct PoseTrack {
    std::vector<std::string> poses;
    std::vector<double> times;  // seconds, increasing
    std::vector<float> values;  // frame-major: values[frame * poses.size() + pose]

    std::size_t frames() const { return times.size(); }
    std::span<const float> frame(std::size_t f) const {
        return std::span<const float>(values).subspan(f * poses.size(), poses.size());
    }
    std::optional<std::size_t> pose(std::string_view name) const;
    void append(double time, std::span<const float> weights);  // weights.size() == poses.size()
};

// CSV with header `time,<pose>,<pose>,...`. Times must be finite, within 0 .. 86400 s and
// increasing; values finite within -10 .. 10 (the actuator stage clamps further). Errors name
// the line and column.
PoseTrack readPoseTrackCsv(std::istream& in, const std::string& sourceName);
PoseTrack readPoseTrackCsvFile(const std::filesystem::path& file);  // "-" is stdin
void writePoseTrackCsv(std::ostream& out, const PoseTrack& track);

// ---------------------------------------------------------------------------------------------
// Files in memory.

// Bytes held as a file in memory (a memfd) that anything taking a path opens through
// /proc/self/fd: an uploaded recording, a line heard live. Nothing touches a disk, and no name
// from a request is ever opened. std::runtime_error when the memory file cannot be made.
class MemoryFile {
  public:
    explicit MemoryFile(const char* name);  // empty
    ~MemoryFile();
    MemoryFile(MemoryFile&& other) noexcept;
    MemoryFile& operator=(MemoryFile&& other) noexcept;

    int fd() const { return fd_; }
    const std::filesystem::path& path() const { return path_; }
    // Appends; std::runtime_error "writing WHAT to memory: why" when it cannot.
    void write(std::string_view bytes, const std::string& what);
    void seal();  // no more writes, growth or shrinking: what was checked is what is read
    // `message` with this file's path named as `what` (a reader's messages name the path;
    // the user knows the file as "the recording" or "live line '...'").
    std::string named(std::string message, const std::string& what) const;

  private:
    int fd_ = -1;
    std::filesystem::path path_;
};

}  // namespace lipsyncd
