// dsp: audio in, phoneme schedule out, by linear prediction (Lewis, shared/seeds/004).
//
//   AudioDecoder        libsndfile: WAV/FLAC/OGG/raw PCM, any rate and channel count → mono
//                       float (mixed, or one chosen channel), read in blocks.
//   StreamResampler     a polyphase FIR (or libsoxr), streaming → the analysis rate (10 kHz);
//                       reports its delay.
//   FrameAnalyzer       one frame: pre-emphasis, Hamming window, autocorrelation, lag window,
//                       white-noise correction, Levinson–Durbin, LPC log spectrum, energy.
//   TemplateSet         spectral templates per phoneme class (config/templates/*.json).
//   FrameClassifier     nearest templates, energy gate with adaptive noise floor, voicing.
//   ViterbiDecoder      the frames' classes decided over time: minimum durations, class
//                       transitions, each frame's visual group before its class; fixed lag.
//   Segmenter           frame labels → segments (hysteresis, minimum durations), streaming.
//   StreamingAnalyzer   all of the above over a stream of samples at any rate, emitting
//                       frames and closed segments as they happen.
//   analyzeFile()       the whole chain over a file, for the command line and tests.
//   ForcedAligner       known words: Viterbi alignment of their phonemes on the classifier's
//                       per-frame distances, in bounded memory (alignFile() over a file).
//   LineFollower        known words heard as they are said: a fixed-lag forced alignment
//                       (the service's live lines; followFile() over a file).
//
// Real-time paths (StreamingAnalyzer::push, LineFollower::push and everything under them) do
// not allocate once constructed, except for the segments handed out.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <lipsyncd/core.hpp>
#include <map>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace lipsyncd::dsp {

// ---------------------------------------------------------------------------------------------
// Audio in.

// Raw PCM description for pipes: "RATE:FORMAT:CHANNELS", FORMAT one of s8 u8 s16 s24 s32 f32 f64
// (little-endian), e.g. "16000:s16:1".
struct RawFormat {
    int sampleRate = 0;
    std::string sampleFormat;
    int channels = 0;
    static RawFormat parse(const std::string& spec);  // throws InputError
};

struct DecodeOptions {
    // -1: mix all channels to mono; otherwise the 0-based channel to keep.
    int channel = -1;
    // With channel == -1: leave this channel out of the mix (a show file's voice channel is
    // analysed, the others are what the audience hears).
    int skipChannel = -1;
};

class AudioDecoder {
  public:
    // Opens a file (type from its content) or, with `raw`, headerless PCM; "-" is stdin.
    static AudioDecoder open(const std::filesystem::path& file, const DecodeOptions& options = {},
                             const std::optional<RawFormat>& raw = std::nullopt);
    AudioDecoder(AudioDecoder&&) noexcept;
    AudioDecoder& operator=(AudioDecoder&&) noexcept;
    ~AudioDecoder();

    int sampleRate() const;
    int channels() const;
    // Frames in the file when known (not for pipes).
    std::optional<std::int64_t> frames() const;
    // Fills `out` with mono samples in [-1, 1]; returns how many, 0 at the end. Non-finite
    // samples become 0 (and are counted). Throws InputError when the data stops making sense.
    std::size_t read(std::span<float> out);
    std::int64_t nonFiniteSamples() const;
    const std::string& name() const;
    // What was wrong with the file that could be read past, each naming the file, for the user
    // (empty: nothing): a header that promises more audio than the file holds (a copy or a
    // download cut short), which is read as far as it goes. Complete once read() has returned 0.
    const std::vector<std::string>& warnings() const;

  private:
    struct State;
    explicit AudioDecoder(std::unique_ptr<State> state);
    void noteEarlyEnd();
    std::unique_ptr<State> state_;
};

// Reads a whole file into memory (tests, training, small tools).
struct MonoAudio {
    std::vector<float> samples;
    int sampleRate = 0;
    std::vector<std::string> warnings;  // AudioDecoder::warnings()
};
MonoAudio readAudioFile(const std::filesystem::path& file, const DecodeOptions& options = {});
// Writes 16-bit PCM WAV.
void writeWavFile(const std::filesystem::path& file, std::span<const std::int16_t> samples,
                  int sampleRate);
void writeWavFile(const std::filesystem::path& file, std::span<const float> samples,
                  int sampleRate);

enum class ResamplerQuality { Low, Medium, High, VeryHigh };
// What the resampler's output waits for. Live input wants little held back: the polyphase FIR at
// any rate it serves (Low, Medium), or libsoxr with small DFT blocks. A whole file does not wait
// for anyone: above 16 kHz libsoxr with its default blocks is faster than the FIR (the same
// passband; outputs agree within 40 dB), and at 16 kHz and below the FIR is both.
enum class ResamplerUse { Live, WholeFile };

class StreamResampler {
  public:
    StreamResampler(double inputRate, double outputRate,
                    ResamplerQuality quality = ResamplerQuality::Medium,
                    std::size_t maxBlock = 4096, ResamplerUse use = ResamplerUse::Live);
    StreamResampler(StreamResampler&&) noexcept;
    StreamResampler& operator=(StreamResampler&&) noexcept;
    ~StreamResampler();

    // Resamples one block (at most maxBlock samples); returns the output samples, which stay
    // valid until the next call. An empty input with `flush` drains what is held back.
    std::span<const float> process(std::span<const float> input, bool flush = false);
    // The resampler's latency in seconds: the longest a sample waited (from going in to coming
    // out) while 10 ms blocks went through a twin of it at construction. libsoxr's own
    // soxr_delay() counts only the filter, not the block it buffers before filtering, and so
    // under-reports what a live path waits for (notes/dsp.md: "measure the resampler's delay").
    double delaySeconds() const { return delaySeconds_; }
    double inputRate() const { return inputRate_; }
    double outputRate() const { return outputRate_; }

  private:
    struct State;
    std::unique_ptr<State> state_;
    double inputRate_, outputRate_;
    double delaySeconds_ = 0;
};

// ---------------------------------------------------------------------------------------------
// LPC analysis of one frame.

inline constexpr int kMaxOrder = 32;

struct AnalysisConfig {
    int analysisRate = 10000;      // Hz; Lewis analyses at 10 kHz
    double hopSeconds = 0.010;     // 100 frames per second
    double windowSeconds = 0.025;  // 25 ms Hamming window
    int order = 12;                // 2 poles per kHz plus 2 for shape (Lewis; notes/dsp.md)
    double preEmphasis = 0.97;
    double lagWindowHz = 60.0;           // Gaussian lag window bandwidth (smooths the spectrum)
    double whiteNoiseCorrection = 1e-4;  // r[0] *= 1 + ε (≈ −40 dB noise floor)
    int spectrumBins = 32;               // log-magnitude points from 0 to analysisRate / 2
    bool spectrumByFft = false;          // evaluate by FFT instead of directly (bench compares)
    // Two features after the spectrum, for what its shape cannot tell: the log normalised
    // prediction error (voiced vowels ≈ −20 dB, fricatives ≈ −5 dB: Lewis's voicing cue), and
    // the frame level relative to recent loud speech (closures and fricatives are quieter than
    // vowels whose spectra they resemble once the gain is gone).
    bool errorFeature = false;
    bool levelFeature = false;
    double levelPeakDecayDbPerSecond = 6;
    // Channel and speaker normalisation (cepstral mean subtraction, Atal 1974, done on the log
    // spectrum): the running mean of the speech frames' spectra is subtracted from every frame.
    // It starts at `spectrumMean` (the training speech's mean: short clips stay near it) worth
    // `meanPriorSeconds` of speech and forgets with `meanMemorySeconds`. Empty: off.
    std::vector<float> spectrumMean;
    double meanPriorSeconds = 2;
    double meanMemorySeconds = 10;
    // Vocal-tract-length warp (Lee & Rose 1996): the spectrum's bins are read at warp times
    // their frequencies (up to the analysis band's top), so a speaker whose formants lie lower
    // than the templates' (a longer vocal tract) is heard with them where the templates expect
    // them, at warp < 1. 1: none. Chosen per speaker by `lipsync calibrate`.
    double warp = 1.0;
    static constexpr double kMinWarp = 0.7, kMaxWarp = 1.4;  // validate()'s bounds

    int featureCount() const { return spectrumBins + errorFeature + levelFeature; }

    int hopSamples() const;
    int windowSamples() const;
    void validate() const;  // throws InputError naming the field
};

// Levinson–Durbin on autocorrelation r[0..order] (Makhoul 1975; Rabiner & Schafer 8.3.2).
struct LpcResult {
    std::array<float, kMaxOrder + 1> a{};  // A(z) = 1 + Σ a[i] z^-i, a[0] = 1
    std::array<float, kMaxOrder> k{};      // reflection coefficients, |k| < 1
    float predictionError = 0;             // E_p (same units as r[0])
    float normalizedError = 1;             // E_p / r[0] in (0, 1]
    int order = 0;                         // the order reached (less when stopped early)
    bool stable = true;                    // false: a reflection coefficient reached |k| ≥ 1
};
LpcResult levinsonDurbin(std::span<const float> r, int order);

struct FrameFeatures {
    double time = 0;        // centre of the frame, seconds from the start of the input
    float energyDb = -120;  // frame RMS in dBFS (before pre-emphasis)
    float normalizedError = 1;
    bool clipped = false;  // many samples at full scale
    bool valid = false;    // false: silent or degenerate; spectrum is flat
    LpcResult lpc;
    // The feature vector: log magnitude of 1/|A| in dB at spectrumBins points, then the extra
    // features the configuration asks for (featureCount() values in all).
    std::vector<float> spectrum;
};

class DirectLpcSpectrum;
class FftLpcSpectrum;
class TemplateMatrix;
class FeatureWeighting;

// The running spectral mean of AnalysisConfig::spectrumMean, over speech frames (valid and
// within `kSpeechBelowPeakDb` of the recent peak), subtracted from each frame's spectrum.
class SpectrumNormaliser {
  public:
    explicit SpectrumNormaliser(const AnalysisConfig& config);
    void apply(FrameFeatures& frame);
    std::span<const float> mean() const { return mean_; }

  private:
    std::vector<float> mean_;
    double weight_, maxWeight_;  // frames' worth of evidence behind the mean, and its cap
    float peakDb_ = -120, peakDecayDb_;
};

class FrameAnalyzer {
  public:
    explicit FrameAnalyzer(const AnalysisConfig& config);
    FrameAnalyzer(FrameAnalyzer&&) noexcept;
    FrameAnalyzer& operator=(FrameAnalyzer&&) noexcept;
    ~FrameAnalyzer();
    // `frame`: windowSamples() samples at the analysis rate. Fills `out` without allocating
    // (out.spectrum must have spectrumBins elements; see makeFeatures()).
    void analyze(std::span<const float> frame, FrameFeatures& out);
    FrameFeatures makeFeatures() const;
    const AnalysisConfig& config() const { return config_; }

  private:
    void measureLevel(std::span<const float> frame, FrameFeatures& out) const;
    void autocorrelate();
    void addExtraFeatures(FrameFeatures& out);

    AnalysisConfig config_;
    std::vector<float> window_, buffer_, lagWindow_;
    std::unique_ptr<DirectLpcSpectrum> direct_;
    std::unique_ptr<FftLpcSpectrum> fft_;
    std::array<float, kMaxOrder + 1> r_{};
    float peakDb_ = -120;  // recent loud level, for the level feature
    std::optional<SpectrumNormaliser> normaliser_;
};

// ---------------------------------------------------------------------------------------------
// Templates and classification.

// Each feature's slope over the newest frame and the `frames` before it, by least squares: the
// dynamic features of speech recognisers (Furui 1986), taken over past frames only, so that a
// live frame waits for none. Frames before the first count as the first. What a network hears
// with its slopeFrames (JawNetwork, ClassNetwork), in training and in use alike.
class FeatureSlopes {
  public:
    FeatureSlopes() = default;
    FeatureSlopes(int frames, std::size_t features);
    // The frame's features, then their slopes per frame, into `out` (2 · features values); the
    // frame becomes the newest. No allocation.
    void push(std::span<const float> frame, std::span<float> out);
    void reset() { seen_ = 0; }

  private:
    std::size_t frames_ = 0, features_ = 0, seen_ = 0;
    std::vector<float> weights_;  // per position 0..frames_: (j − frames_/2) / Σ (j − frames_/2)²
    std::vector<float> past_;  // the last frames_ frames, [seen mod frames_][feature]
};

// A network's slopeFrames: 0, its inputs are the frame's features; n > 0, the features and then
// each one's slope over the frame and the n before it (FeatureSlopes), twice the inputs.
inline constexpr int kMaxSlopeFrames = 16;
constexpr std::size_t networkInputs(std::size_t features, int slopeFrames) {
    return slopeFrames > 0 ? 2 * features : features;
}

// What a network hears of each frame in turn, as its slopeFrames say: the frame's own features,
// or those and their slopes. The classifier and the trainer both feed every frame through one.
class NetworkInput {
  public:
    NetworkInput() = default;
    NetworkInput(int slopeFrames, std::size_t features);
    // The input for `frame` (its features), which becomes the newest: the frame itself without
    // slopes, else a buffer valid until the next push. No allocation.
    std::span<const float> push(std::span<const float> frame);
    void reset() { slopes_.reset(); }

  private:
    FeatureSlopes slopes_;
    std::vector<float> input_;  // empty: no slopes
};

// How far the jaw opens, heard from one frame's features (the same vector the templates are
// matched on): a network with one hidden layer of rectified units and a logistic output, trained on
// labelled speech against the jaw heights of the frames' phoneme classes (TemplateTrainer). A
// multilayer perceptron estimates from the acoustic features directly what a classifier would
// pass through a class decision (Bourlard & Morgan 1994); trained on many voices it pools what
// the frames of one jaw height share, where nearest templates follow one voice's spectrum.
struct JawNetwork {
    std::vector<float> inputMean, inputScale;       // per input: x' = (x − mean) · scale
    std::vector<std::vector<float>> hiddenWeights;  // per input: its weight to each unit
    std::vector<float> hiddenBias;                  // per hidden unit
    std::vector<float> outputWeights;               // per hidden unit
    float outputBias = 0;
    int slopeFrames = 0;  // what it hears beside the frame (networkInputs)

    std::size_t hiddenUnits() const { return hiddenBias.size(); }
    std::size_t inputsFor(std::size_t features) const {
        return networkInputs(features, slopeFrames);
    }
    // The jaw height in [0, 1] (0 closed). `inputs`: inputsFor(featureCount()) values, a
    // NetworkInput's of the frame.
    float operator()(std::span<const float> inputs) const;
    // InputError naming `source` and the field when sizes disagree or a value is not finite.
    void validate(std::size_t features, const std::string& source) const;
};

// Which class a frame belongs to, heard from the same features by the same kind of network with
// a softmax output over the classes (Bourlard & Morgan 1994, the hybrid of a multilayer
// perceptron and a hidden Markov model): its posteriors divided by the classes' shares of the
// training frames are scaled likelihoods, which the classifier adds to the template distances
// (ClassifierConfig::classNetworkDb) for the decoder to weigh (the aligner weighs the templates
// alone: FrameClassifier::templateDistances).
struct ClassNetwork {
    std::vector<std::string> classes;               // output order: phoneme set names
    std::vector<float> inputMean, inputScale;       // per input: x' = (x − mean) · scale
    std::vector<std::vector<float>> hiddenWeights;  // per input: its weight to each unit
    std::vector<float> hiddenBias;                  // per hidden unit
    std::vector<std::vector<float>> outputWeights;  // per hidden unit: its weight to each class
    std::vector<float> outputBias;                  // per class
    std::vector<float> logPrior;                    // per class: ln of its share of the frames
    int slopeFrames = 0;  // what it hears beside the frame (networkInputs)

    std::size_t hiddenUnits() const { return hiddenBias.size(); }
    std::size_t inputsFor(std::size_t features) const {
        return networkInputs(features, slopeFrames);
    }
    // ln p(c | x) − priorScale · ln p(c) per class into `out` (classes.size() values), up to a
    // constant of the frame's (the softmax's normaliser, the same for every class); `scratch`:
    // at least hiddenUnits() values. No allocation. priorScale 1: the hybrid's scaled
    // likelihoods; 0: the posteriors themselves (ClassifierConfig::classPriorScale).
    void scaledLogLikelihoods(std::span<const float> features, std::span<float> out,
                              std::span<float> scratch, float priorScale) const;
    // Per output, its class's index in `set` (-1: not in the set).
    std::vector<int> setIndices(const PhonemeSet& set) const;
    // The hybrid's term added to `distances` (indexed by set index): each class the network
    // knows (`setIndices` ≥ 0) whose distance is finite lies `dbPerNat` dB further off per nat
    // its scaled likelihood falls short of the likeliest class's. `likelihoods` (classes.size()
    // values) and `scratch` (hiddenUnits()) are working space. No allocation.
    void addToDistances(std::span<const float> features, std::span<const int> setIndices,
                        float dbPerNat, float priorScale, std::span<float> distances,
                        std::span<float> likelihoods, std::span<float> scratch) const;
    // InputError naming `source` and the field when sizes disagree or a value is not finite.
    void validate(std::size_t features, const std::string& source) const;
};

// Spectral templates: per class one or more log spectra (cluster means), on the grid of the
// analysis configuration they were trained with, and per-bin weights for the distance.
// File format: config/templates/README.md.
struct TemplateSet {
    struct ClassTemplates {
        std::string phoneme;
        std::vector<std::vector<float>> spectra;
        std::size_t frames = 0;  // training frames behind these (for reports)
    };
    AnalysisConfig analysis;
    std::vector<float> binWeights;  // distance weights per bin (inverse variance), sum = bins
    // Optional full distance transform W (featureCount() rows of featureCount() values, lower
    // triangular): the distance is ‖W(x − t)‖, a Mahalanobis distance under the pooled
    // within-class covariance, in place of the per-bin weights (which are then all 1). Empty: the
    // per-bin weights alone (a diagonal covariance).
    std::vector<std::vector<float>> whitening;
    std::vector<ClassTemplates> classes;
    // Optional: the jaw heard from each frame (FrameLabel::jaw). Without it the jaw comes from
    // the class distances (ClassifierConfig::jawSpreadDb).
    std::optional<JawNetwork> jawNetwork;
    // Optional: scaled class likelihoods added to the distances (ClassifierConfig::classNetworkDb).
    std::optional<ClassNetwork> classNetwork;
    // Optional: dB added to a class's distance (after the class network's term), per class name:
    // a correction of the classes' priors for real voices, which the training speech (mostly
    // espeak-ng) does not give. Fitted on voices held out of training by
    // scripts/fit-class-bias.py; the forced aligner, whose classes the words give, weighs the
    // templates' distances without it.
    std::map<std::string, float> classBiasDb;
    std::string description;

    static TemplateSet load(const std::filesystem::path& file);  // validates; InputError
    static TemplateSet loadDefault();                            // config/templates/default.json
    // "" (the default), a name in config/templates ("default") or a file: what `--templates`
    // and lipsyncd's `templates` key both take.
    static TemplateSet named(const std::string& nameOrPath);
    void save(const std::filesystem::path& file) const;
    void validate(const std::string& source) const;
};

struct FrameLabel {
    double time = 0;
    int phoneme = 0;  // index into the PhonemeSet
    int runnerUp = 0;
    float distance = 0, runnerUpDistance = 0;
    float confidence = 0;  // in [0, 1], from the margin between best and runner-up
    float energyDb = -120;
    float noiseFloorDb = -120;
    bool voiced = false;
    bool silent = true;  // below the energy gate
    // How far the jaw opens for this frame, 0 on a silent frame: the template set's jaw
    // network, or without one the class scores' jaw heights (PhonemeSet) weighted by how near
    // each class is (ClassifierConfig::jawSpreadDb). Either way a frame torn between two open
    // vowels still says "open" even when the pick between them is wrong.
    float jaw = 0;
};

struct ClassifierConfig {
    // A frame is silent below noise floor + margin ... (real dev speakers, worst one: 12 dB
    // 45.8 %, 9 dB 47.9 %, 8 dB 48.6 %, 6 dB 49.5 % but silence recall falling; espeak-ng dev
    // unchanged within 0.2 points).
    float silenceMarginDb = 8;
    float absoluteSilenceDb = -55;        // ... or below this level whatever the floor
    float voicingThreshold = 0.25;        // normalised prediction error below this: voiced (Lewis)
    float noiseFloorRiseDbPerSecond = 3;  // the floor follows quiet frames at once, rises slowly
    // The floor starts at the first frame's level when it is at most this: recordings begin with
    // the room, and a floor that starts far below the room's noise calls the noise speech until it
    // has crept up (real recordings: silence 12 % right on short clips with a −52 dBFS room).
    float maxStartFloorDb = -45;
    // ... or this far below the recent speech peak (decaying `peakDecayDbPerSecond`): a room
    // whose noise the floor has not caught up with yet (a clip that starts with speech) is
    // still far quieter than the voice. 0: off. Tuned on real training speakers left out of
    // the templates (visual groups: off 40.1 %, 40 dB 40.1 %, 30 dB 41.7 %, 25 dB 41.1 %) and
    // the espeak-ng dev corpus (25 dB lost 3 points, 30 dB none).
    float silenceBelowPeakDb = 30;
    float peakDecayDbPerSecond = 6;
    // FrameLabel::jaw: class c weighs exp(−(d_c − d_best) / jawSpreadDb), d in dB of distance.
    float jawSpreadDb = 0.5f;
    // With a class network (TemplateSet::classNetwork): a class whose scaled likelihood lies
    // one nat below the frame's likeliest lies this many dB further off. 0: templates alone.
    // Real training speakers left out of their own set (klettres-en-gb / asterisk-en-allison,
    // 32 units): 0.25 / 0.5 / 1 / 2 dB gave visual groups 75.6 / 76.8 / 76.3 / 75.6 % and
    // 44.6 / 45.3 / 45.0 / 44.8 %, false closures 13.3 / 11.7 / 11.7 / 10.8 % and
    // 14.5 / 13.5 / 12.3 / 11.7 %; 1 dB keeps the groups and closes the mouth less by mistake.
    float classNetworkDb = 1.0f;
    // How much of the classes' training shares the class network's posteriors are divided by:
    // p(c | x) / p(c)^scale. Bourlard & Morgan (1994) divide by the whole prior, so that the
    // decoder's own transition model supplies it; with this decoder, whose transitions already
    // favour the common classes, the whole division favoured rare ones too much. Chosen on the
    // voices held out for decisions (the shipped recipe's sets, klettres-en-gb and
    // asterisk-en-allison each left out, and the six tune voices; audio only, visual groups
    // summed over the eight): 1 / 0.7 / 0.5 / 0.3 / 0 gave 380.5 / 388.1 / 393.5 / 398.8 /
    // 404.5 points, every voice rising, espeak-ng dev 78.0 / 78.9 / 79.6 / 79.9 / 80.1 %, but
    // false closures rising too (summed 73.6 / 82.9 / 89.0 / 92.7 / 96.7 points). The mouth
    // shutting in a vowel is the error an audience sees: at 0.5 a voice's false closures rise
    // at most 2.3 points (asterisk-ru-f 4.5), at 0 up to 5.1.
    float classPriorScale = 0.5f;
};

class FrameClassifier {
  public:
    FrameClassifier(const TemplateSet& templates, const PhonemeSet& set,
                    const ClassifierConfig& config = {});
    FrameLabel classify(const FrameFeatures& frame);
    // Distance from the frame to each class (best template, the class network's term and the
    // set's class bias), indexed by phoneme set index; +inf for classes without templates.
    // Valid after classify().
    std::span<const float> distances() const { return distances_; }
    // The templates' distances alone, without the class network's term or the class bias: what
    // the forced aligner weighs, with a share of the rest (AlignerConfig::classNetworkShare; all
    // of the network's term moved boundaries away from the reference ones on the real training
    // speakers left out of it: visual groups 84.9 / 53.5 % → 80.8 / 51.1 % for klettres-en-gb /
    // asterisk-en-allison).
    std::span<const float> templateDistances() const {
        return templateDistances_.empty() ? distances_ : std::span<const float>(templateDistances_);
    }
    // From now on, each frame's least squared distance per block of eight templates
    // (TemplateMatrix) is kept, for a second pass on templates of which only some moved to take
    // the others' from (realign in AlignFile.cpp). +inf for a frame without a spectrum.
    void recordBlockDistances();
    std::span<const float> blockDistances() const { return blockDistances_; }
    void reset();

  private:
    float expectedJaw(float bestDistance) const;

    const PhonemeSet* set_;
    ClassifierConfig config_;
    std::shared_ptr<const TemplateMatrix> matrix_;  // every template, laid out for the distances
    std::vector<float> scaledFrame_;
    std::vector<float> distances_;
    std::vector<float> blockDistances_;  // empty unless recordBlockDistances()
    std::vector<float> jawOf_;           // per class: its jaw height (0 where the set gives none)
    std::optional<JawNetwork> jawNetwork_;
    void addClassNetwork(std::span<const float> input);
    std::optional<ClassNetwork> classNetwork_;
    std::vector<int> networkClass_;  // per network output: its set index (-1: none)
    void addClassBias();
    std::vector<float> classBias_;  // per class, dB (TemplateSet::classBiasDb); empty: none
    std::vector<float> likelihoods_, hiddenUnits_;  // the class network's, per frame
    NetworkInput classInput_, jawInput_;            // what each network hears of the frame
    bool jawHearsClassInput_ = false;               // the same slopes: one NetworkInput for both
    std::vector<float> templateDistances_;
    int sil_ = 0;
    float noiseFloorDb_ = 0;
    float peakDb_ = -120;
    bool floorInitialised_ = false;
    double lastTime_ = 0;
};

struct SegmenterConfig {
    // Shorter runs are flicker, not phonemes. Measured on the espeak-ng dev corpus (frame
    // accuracy, common set): 50/30/60 ms 61.4 %, 30/20/40 ms 64.9 %, 20/20/20 ms 63.3 %,
    // none 59.1 %. Short holds also keep the streaming delay (longest + a hop) at 50 ms.
    double minVowelSeconds = 0.03;
    double minConsonantSeconds = 0.02;
    double minSilenceSeconds = 0.04;
    float switchMargin = 0.0f;  // extra confidence a new class needs (hysteresis)
    // A silence shorter than this between two speech segments is a stop's closure (the
    // silent hold before the burst of t, k, p), not a pause, and takes closureClass, as
    // phonetic labels and espeak-ng's own timings count it (0: every silence stays one).
    // Tune voices, audio only (visual groups summed over six; score as in
    // docs/measurements.md): off 283.4 (685.0), 0.06 / 0.08 / 0.1 / 0.12 / 0.15 / 0.2 s
    // 288.0 / 289.6 / 290.9 / 291.2 / 291.3 / 290.9, jaw r unchanged. From 0.1 s on, the
    // espeak-ng dev voices lose points (their pauses between words are that short): 0.08.
    double stopClosureSeconds = 0.08;
    std::string closureClass = "d";  // t d n: the commonest stop
};

// Turns frame labels into segments. Streaming: push() frames as they come; closed segments
// come out once no later frame can change them. The delay is bounded (delaySeconds()).
class Segmenter {
  public:
    Segmenter(const PhonemeSet& set, double hopSeconds, const SegmenterConfig& config = {});
    // Returns the segments closed by this frame (usually none; at most a few).
    std::span<const PhonemeSegment> push(const FrameLabel& label);
    std::span<const PhonemeSegment> finish(double endTime);
    double delaySeconds() const;

  private:
    struct Run {
        int phoneme;
        double start, end;
        float confidenceSum;
        int frames;
    };
    // `followed`: another run comes after this one.
    void emit(const Run& run, bool followed);
    double minDuration(int phoneme) const;
    bool tooShort(const Run& run) const;
    void absorbIfFlicker(std::size_t closed);
    void settle(bool final);

    const PhonemeSet* set_;
    double hop_;
    SegmenterConfig config_;
    std::vector<Run> pending_;  // runs not yet final
    std::vector<PhonemeSegment> out_;
    double emittedUntil_ = 0;
    int closure_ = -1;            // closureClass's index (-1: stop closures off)
    bool lastWasSpeech_ = false;  // the segment emitted last was not silence
};

// ---------------------------------------------------------------------------------------------
// Temporal decoding.

// Which class follows which, and how long each lasts at least: the language's phonotactics as
// seen in espeak-ng phonemisations of text (scripts/make-transitions.sh; format in
// config/decoder/README.md).
struct TransitionModel {
    std::vector<std::string> classes;         // common-set names, the rows and columns
    std::vector<std::vector<float>> logProb;  // [from][to]: log P(to | from), from != to
    std::vector<int> minFrames;               // per class: shortest run, in hops
    std::string description;

    static TransitionModel load(const std::filesystem::path& file);  // validates; InputError
    static TransitionModel loadDefault();  // config/decoder/english-transitions.json
    void validate(const std::string& source) const;
};

struct DecoderConfig {
    bool enabled = true;
    // Fixed lag: a frame's class is decided this long after it arrives (streaming). Negative:
    // offline, every frame decided at the end from the whole input.
    // On the dev corpora 30–100 ms decode as well as offline (within half a point); 0 (no
    // look-ahead) loses up to 6 points.
    double lagSeconds = 0.05;
    float distanceScale = 1.0f;     // emission cost per dB of template distance
    float transitionWeight = 1.0f;  // weight of −log P(to | from)
    float switchPenalty = 1.0f;     // extra cost of any class change (insertion penalty)
    float gatedSpeechPenalty =
        4.0f;                  // cost of a non-silence class on a frame the gate calls silent
    float silenceCost = 2.0f;  // cost of silence on a frame above the gate, over the best
    // The visual group before the class: a speech class also pays groupShare · groupSpreadDb ·
    // ln(M_top / M_its group), M a group's share of the frame, Σ exp(−(d − d_best) /
    // groupSpreadDb) over its classes. A frame torn between the open vowels and one rounded
    // one then says "open" where the nearest class alone said "rounded". 0: off. Chosen on the
    // tune voices (audio only, score as in docs/measurements.md): share 0 / 1 / 2 / 4 at
    // spread 1 dB gave 690.94 / 696.59 / 698.00 / 699.96 (live 653.65 / – / 659.33 / 660.06),
    // espeak-ng dev 81.7 / 81.1 / 80.8 / 80.3 % (worst voice 74.3 / 74.1 / 74.2 / 73.3 %); a
    // group's mean in place of its sum favoured the one-class groups (bmp, f) and lost 11 points.
    float groupShare = 2.0f;
    float groupSpreadDb = 1.0f;
};

// Viterbi over classes, each a chain of minFrames states (a minimum duration) with a self loop
// on its last; between classes the transition model and a switch penalty. Emissions are the
// classifier's per-class distances (Lewis: classification by spectral distance; the decoder
// picks the sequence, not the frame: notes/dsp.md "HMM/Viterbi decoding over template classes
// with duration penalties"). Does not allocate per frame once constructed (fixed lag).
class ViterbiDecoder {
  public:
    ViterbiDecoder(const TransitionModel& model, const PhonemeSet& set, double hopSeconds,
                   const DecoderConfig& config = {});
    // One frame's label (from the classifier) and distances (FrameClassifier::distances()).
    // Returns the labels now decided: one per push in fixed-lag mode once the lag has filled,
    // none offline.
    std::span<const FrameLabel> push(const FrameLabel& label, std::span<const float> distances);
    // Decides everything still pending.
    std::span<const FrameLabel> finish();
    double delaySeconds() const;  // the lag (0 offline: nothing is emitted before the end)
    int lagFrames() const { return lag_; }

  private:
    void step(const FrameLabel& label, std::span<const float> distances);
    int backtrack(std::size_t frameOffset) const;
    void decideUpTo(std::size_t end, int lastState);
    void addGroupCosts(std::span<const float> distances, float best);

    std::size_t classes_ = 0, states_ = 0;
    std::vector<int> stateClass_, firstState_, lastState_;
    std::size_t stride_ = 0;         // classes rounded up to a multiple of 8
    std::vector<float> transition_;  // [from * stride + to], costs
    DecoderConfig config_;
    int lag_ = 0;  // frames; < 0 offline
    double hop_ = 0.01;
    int sil_ = 0;
    std::vector<float> score_, next_, emission_;
    std::vector<float> exitScore_;     // per class: the score of its last state
    std::vector<float> enter_;         // per class: the best score entering it this frame
    std::vector<int> entryFrom_;       // per class: the class that entry comes from (−1: none)
    std::vector<std::uint16_t> back_;  // [frame slot][state]: the state before
    std::vector<FrameLabel> pending_;  // labels not yet decided, oldest first
    std::size_t frames_ = 0, decided_ = 0;
    std::vector<FrameLabel> out_;
    std::vector<int> classGroup_;   // per class: its visual group's index (−1: silence)
    std::vector<float> groupMass_;  // per group: its share of the frame, then its cost
};

// ---------------------------------------------------------------------------------------------
// The whole chain.

struct FrontEndConfig {
    AnalysisConfig analysis;  // overridden by the templates' own analysis settings
    ClassifierConfig classifier;
    SegmenterConfig segmenter;
    DecoderConfig decoder;
    std::optional<TransitionModel> transitions;  // decoder.enabled and unset: loadDefault()
    ResamplerQuality resamplerQuality = ResamplerQuality::Medium;
    ResamplerUse resamplerUse = ResamplerUse::Live;  // analyzeFile and alignFile: WholeFile
};

// Resampling and framing: samples at any rate in, analysed frames (features) out, every hop.
class FrameStream {
  public:
    using Sink = std::function<void(const FrameFeatures&)>;
    FrameStream(const AnalysisConfig& config, double inputRate,
                ResamplerQuality quality = ResamplerQuality::Medium,
                ResamplerUse use = ResamplerUse::Live);
    // Any block size; `sink` is called for every frame completed.
    void push(std::span<const float> samples, const Sink& sink);
    // Drains the resampler and analyses the frames centred inside the audio.
    void finish(const Sink& sink);
    double endTime() const;  // seconds of audio seen (at the analysis rate)
    double resamplerDelaySeconds() const { return resampler_.delaySeconds(); }
    const AnalysisConfig& config() const { return analyzer_.config(); }

  private:
    void append(std::span<const float> resampled, const Sink& sink);
    void analyzeReadyFrames(const Sink& sink);

    StreamResampler resampler_;
    FrameAnalyzer analyzer_;
    FrameFeatures features_;
    std::vector<float> buffer_;  // analysis-rate samples not yet consumed
    std::size_t fill_ = 0;
    std::int64_t consumed_ = 0;  // analysis-rate samples dropped from the front of buffer_
    std::int64_t produced_ = 0;  // analysis-rate samples produced so far
    std::int64_t nextFrameStart_ = 0;
    double endTime_ = 0;
};

// Features of every frame of a file (training, calibration); `warnings`, when given, gets the
// decoder's (AudioDecoder::warnings()).
std::vector<FrameFeatures> analyzeFrames(const std::filesystem::path& file,
                                         const AnalysisConfig& config,
                                         const DecodeOptions& decode = {},
                                         std::vector<std::string>* warnings = nullptr);

class StreamingAnalyzer {
  public:
    struct Frame {
        FrameFeatures features;
        FrameLabel label;
    };
    using FrameSink = std::function<void(const Frame&)>;
    using SegmentSink = std::function<void(const PhonemeSegment&)>;

    StreamingAnalyzer(const TemplateSet& templates, const PhonemeSet& set, double inputRate,
                      const FrontEndConfig& config = {});
    void onFrame(FrameSink sink) { frameSink_ = std::move(sink); }
    void onSegment(SegmentSink sink) { segmentSink_ = std::move(sink); }

    // Any block size. Sinks are called from inside.
    void push(std::span<const float> samples);
    // All of a decoder's input, in blocks (a file's whole analysis: then finish()); returns how
    // many samples were read.
    std::int64_t pushAll(AudioDecoder& decoder);
    void finish();
    // From a sound entering push() to the segment that covers it closing: resampler delay, a
    // window, the decoder's lag and the segmenter's hold.
    double latencySeconds() const;
    double resamplerDelaySeconds() const { return frames_.resamplerDelaySeconds(); }
    // The classifier's distance to each class for the frame being handed to the frame sink
    // (FrameClassifier::distances()); valid only inside the sink.
    std::span<const float> distances() const { return classifier_.distances(); }
    std::span<const float> templateDistances() const { return classifier_.templateDistances(); }
    // FrameClassifier::recordBlockDistances() and blockDistances().
    void recordBlockDistances() { classifier_.recordBlockDistances(); }
    std::span<const float> blockDistances() const { return classifier_.blockDistances(); }

  private:
    void onFeatures(const FrameFeatures& features);
    void segment(const FrameLabel& label);

    TemplateSet templates_;
    FrontEndConfig config_;
    FrameStream frames_;
    FrameClassifier classifier_;
    Segmenter segmenter_;
    std::optional<ViterbiDecoder> decoder_;
    FrameSink frameSink_;
    SegmentSink segmentSink_;
    FrameStream::Sink featureSink_;
    Frame frame_;
};

struct AnalysisResult {
    PhonemeSchedule schedule;
    LevelTrack levels;                             // every frame's RMS level (dBFS)
    std::vector<StreamingAnalyzer::Frame> frames;  // only when asked for
    double durationSeconds = 0;
    int inputRate = 0;
    double resamplerDelaySeconds = 0;
    std::int64_t nonFiniteSamples = 0;
    std::vector<std::string> warnings;  // the decoder's (AudioDecoder::warnings())
};

// ---------------------------------------------------------------------------------------------
// Loudness.

// Frame RMS levels (dBFS) of audio in memory, `frameRate` frames a second, each over a window
// of `windowSeconds` centred on the frame.
LevelTrack measureLevels(std::span<const float> samples, int sampleRate, double frameRate = 100,
                         double windowSeconds = 0.03);
LevelTrack measureLevels(std::span<const std::int16_t> samples, int sampleRate,
                         double frameRate = 100, double windowSeconds = 0.03);  // 16-bit PCM

// A loudness envelope follower, as the jaw boards sold for animatronics drive a servo: the
// amplitude envelope (fast attack, slower release), a noise gate, and a gain set so that the
// voice's speaking level opens the jaw fully. One value in [0, 1] per level frame.
struct EnvelopeFollowerConfig {
    double attackSeconds = 0.01, releaseSeconds = 0.06;
    double gateBelowPeakDb = 35;    // quieter than this below the loudest frame: closed
    double fullAtPercentile = 0.9;  // of the frames above the gate: fully open
};
std::vector<float> followEnvelope(const LevelTrack& levels,
                                  const EnvelopeFollowerConfig& config = {});

// ---------------------------------------------------------------------------------------------
// Training and evaluation.

// The analysis new template sets are trained with: both extra features on (on the dev corpus
// the level feature alone added 4 points of frame accuracy).
inline AnalysisConfig withExtraFeatures(AnalysisConfig c = {}) {
    c.errorFeature = c.levelFeature = true;
    return c;
}

struct TrainingOptions {
    AnalysisConfig analysis = withExtraFeatures();
    // Cluster means per class (paper 001, section 4: a cluster per phoneme; more catch speaker
    // and context variety). On the espeak-ng dev corpus, 1/2/5/8/16/24 clusters gave 36/47/54/
    // 59/61/63 % frame accuracy; 16 keeps the classifier near 1 µs a frame (bench/).
    int clustersPerClass = 16;
    std::size_t minFramesPerCluster = 40;
    double boundaryMarginSeconds = 0.02;  // frames this near a label boundary are transitions
    float maxBelowPeakDb = 35;  // frames this far below the utterance's peak are not speech
    std::uint32_t seed = 1;     // k-means++ seeding: fixed, so training is reproducible
    // Distance under the full pooled within-class covariance (TemplateSet::whitening) instead of
    // per-bin variances: neighbouring bins of an LPC spectrum move together (a formant shifts
    // several at once), which a per-bin weight counts again for every bin it touches.
    bool fullCovariance = false;
    // The jaw network (TemplateSet::jawNetwork) trained beside the templates: hidden units (0:
    // none) and passes over the frames. Real dev speakers (klettres-en / ktuberling-en /
    // festvox-ru), frame by frame, jaw r against the labels' jaw heights: 0.83 / 0.72 / 0.68
    // from the class distances, 0.86 / 0.75 / 0.75 with 32 units after 4 passes; more context
    // (the frames 20–60 ms before) fitted espeak-ng better and real voices worse.
    int jawHiddenUnits = 32;
    int jawEpochs = 4;
    // The class network (TemplateSet::classNetwork): hidden units (0: none) and passes. On the
    // real training speakers each left out of their own set (klettres-en-gb /
    // asterisk-en-allison, visual groups from audio through the decoder), 32 / 64 / 128 units
    // after 4 passes gave 76.8 / 75.5 / 75.8 % and 45.3 / 44.5 / 45.5 %, 64 after 8 passes
    // 75.4 / 44.3 %; the templates alone 73.9 / 42.4 %.
    int classHiddenUnits = 32;
    int classEpochs = 4;
    // Each network also hears each feature's slope over the frame and this many before it
    // (their slopeFrames; 0: the frame alone).
    int jawSlopeFrames = 0;
    int classSlopeFrames = 0;
};

// Options for a TemplateTrainer that keeps the frames `set`'s own networks learn from (its
// analysis, its networks' hidden units), for TemplateTrainer::fineTuneNetworks; no network in
// the set: none kept (networkFrames() stays 0).
TrainingOptions fineTuningOptions(const TemplateSet& set);

// Builds templates as cluster means of labelled frames (k-means per class on LPC spectra, the
// viseme clusters of paper 001 section 4 applied to spectra) and distance weights from the pooled
// within-class variance per bin, or its whole covariance (TrainingOptions::fullCovariance).
class TemplateTrainer {
  public:
    TemplateTrainer(const TrainingOptions& options, const PhonemeSet& set);
    // Frames of one utterance with its reference labels (common-set names).
    void addUtterance(std::span<const FrameFeatures> frames, const PhonemeSchedule& labels);
    // Frames of a sustained sound of one class (calibration recordings).
    void addSustained(std::span<const FrameFeatures> frames, const std::string& phoneme);
    std::size_t frames(const std::string& phoneme) const;
    // Throws InputError when no class has enough frames.
    TemplateSet build(const std::string& description) const;
    // `base` with its networks trained further on the frames of the utterances added (one
    // speaker's: calibration), `epochs` passes at Adam's step size `rate`; its templates as they
    // are. Frames of a class the class network does not know teach only the jaw network. Needs
    // network frames (TrainingOptions' hidden units above 0) and the base's analysis.
    TemplateSet fineTuneNetworks(TemplateSet base, int epochs, float rate) const;
    std::size_t networkFrames() const { return classTargets_.size(); }

  private:
    void addFrame(const FrameFeatures& frame, std::size_t phoneme);
    void addNetworkFrames(std::span<const FrameFeatures> frames, const PhonemeSchedule& labels,
                          float peak);
    std::optional<ClassNetwork> trainClasses(std::size_t bins) const;
    // The networks' inputs, a row per network frame, for networks hearing `slopeFrames`.
    const std::vector<float>& inputsWith(int slopeFrames) const;
    template <class Network>
    const std::vector<float>& tuningInputs(const Network& net, std::size_t features) const;
    TrainingOptions options_;
    const PhonemeSet* set_;
    std::vector<std::vector<std::vector<float>>> spectra_;  // [class][frame][bin]
    // The networks' frames: per frame the jaw height and the class index, and their inputs per
    // slopeFrames a network hears (one copy when both hear alike: NetworkInput).
    std::vector<float> jawTargets_;
    std::vector<std::uint16_t> classTargets_;
    std::map<int, std::vector<float>> inputs_;
    bool jawUsable_ = true;  // every labelled class has a jaw height
};

// Trains a JawNetwork on `inputs` (targets.size() rows of `features` values) against `targets`
// in [0, 1]: squared error, Adam (Kingma & Ba 2015), mini-batches in an order fixed by `seed`.
JawNetwork trainJawNetwork(std::span<const float> inputs, std::span<const float> targets,
                           std::size_t features, int hiddenUnits, int epochs, std::uint32_t seed);

// Trains a ClassNetwork on `inputs` (labels.size() rows of `features` values) against each
// row's class index into `classes`: cross-entropy through the softmax, Adam, mini-batches in an
// order fixed by `seed`. Every class needs at least one row.
ClassNetwork trainClassNetwork(std::span<const float> inputs, std::span<const std::uint16_t> labels,
                               std::span<const std::string> classes, std::size_t features,
                               int hiddenUnits, int epochs, std::uint32_t seed);

// Fine-tuning: `base` trained further on one speaker's frames (labels index `base.classes`;
// targets as trainJawNetwork's), from its own weights and input standardisation, Adam at step
// size `rate`. The class network keeps the base's priors: the scaled likelihoods stay divided by
// the shares of the speech it was first trained on.
ClassNetwork fineTuneClassNetwork(const ClassNetwork& base, std::span<const float> inputs,
                                  std::span<const std::uint16_t> labels, int epochs, float rate,
                                  std::uint32_t seed);
JawNetwork fineTuneJawNetwork(const JawNetwork& base, std::span<const float> inputs,
                              std::span<const float> targets, int epochs, float rate,
                              std::uint32_t seed);

// Frame-by-frame agreement of a schedule with reference labels, sampled every `step` seconds.
struct ScheduleScore {
    std::size_t frames = 0, correct = 0, groupCorrect = 0;
    std::vector<std::vector<std::size_t>> confusion;  // [reference][hypothesis], set indices

    double accuracy() const { return frames ? static_cast<double>(correct) / frames : 0.0; }
    double groupAccuracy() const {
        return frames ? static_cast<double>(groupCorrect) / frames : 0.0;
    }
    void add(const ScheduleScore& other);
};
ScheduleScore scoreSchedule(const PhonemeSchedule& hypothesis, const PhonemeSchedule& reference,
                            const PhonemeSet& set, double step = 0.01);

// How far a schedule's phoneme boundaries lie from the reference's: the forced aligner's timing,
// which visual groups measure only where the classes on either side differ in group. Each
// reference boundary (a change of phoneme) is matched with the nearest hypothesis boundary
// between the same two phonemes; one without such a partner within `missedAfter` seconds is
// missed and counts at that error.
struct BoundaryScore {
    std::vector<double> errors;  // seconds, one per reference boundary
    std::size_t missed = 0;

    void add(const BoundaryScore& other);
    // The error at fraction p (0..1) of the sorted errors, in seconds (0 with no boundaries).
    double percentile(double p) const;
    // The share of boundaries placed within `seconds` (0..1; 0 with no boundaries).
    double shareWithin(double seconds) const;
};
BoundaryScore scoreBoundaries(const PhonemeSchedule& hypothesis, const PhonemeSchedule& reference,
                              double missedAfter = 0.1);

AnalysisResult analyzeFile(const std::filesystem::path& file, const TemplateSet& templates,
                           const PhonemeSet& set, const FrontEndConfig& config = {},
                           const DecodeOptions& decode = {},
                           const std::optional<RawFormat>& raw = std::nullopt,
                           bool keepFrames = false);

// ---------------------------------------------------------------------------------------------
// Forced alignment: the words are known, only their timing comes from the audio.

// One written word and the phonemes it is spoken with (set names), each with the duration the
// synthesiser gives it at its own rate (only the durations are used, not the times).
struct ScriptWord {
    std::string text;
    PhonemeSchedule phonemes;
    // Other ways the word is said (common reductions: "and" as /ən/ or /n/), aligned as
    // parallel paths; the best-fitting one wins. Durations as in `phonemes`.
    std::vector<PhonemeSchedule> alternatives = {};
};

struct AlignerConfig {
    // Emission cost of a class in a frame: weight · (d² − d_min²), d the classifier's distance
    // (dB) to the class and d_min the frame's nearest; the nearest class costs nothing. Retuned
    // on the training corpus for the templates trained with real speakers (24 clusters a
    // class): 0.02/0.03/0.05/0.08 gave boundary p95 43.5/43.5/45.5/62.5 ms.
    float distanceWeight = 0.03f;
    // Frames below the energy gate: cost of a vowel, and of a consonant (a stop's closure and a
    // weak fricative are quiet by nature).
    float speechInSilenceCost = 2.0f;
    float consonantInSilenceCost = 0.3f;
    // The other way round: silence (a pause, the lead-in and the tail) in a frame above the
    // energy gate. Free, it took the weak end of a word (an offglide, a final nasal, /l/ or /z/)
    // for the pause after it, and real words came out at their minimum duration. Tuned on the
    // real training speakers (`lipsync eval --align`, asterisk-en-allison / klettres-en-gb
    // visual groups; 0 / 0.25 / 0.5 / 1 gave 60.4 / 62.6 / 62.2 / 61.1 % and
    // 88.7 / 88.1 / 87.4 / 86.9 %, jaw r 0.65 / 0.85 → 0.65 / 0.87 from 0.25 on) and the
    // espeak-ng training corpus (boundary p95 43.5 → 42.5 ms from 0.25 on).
    float silenceInSpeechCost = 0.25f;
    // The same cost when a line is followed as it is said (LineFollower), where each frame is
    // decided from the best partial path. Offline every word must be placed before the end, so
    // a cheap pause is paid back there; a partial path has no such debt, and one still in the
    // lead-in (or a pause) at 0.25 a frame beat the words on voices the templates fit less well
    // than that: the telephone prompts, said from their first sample, were followed as silence
    // for most of each word. The tune voices (`lipsync eval --align --follow-lag 0.1`, score as
    // in docs/measurements.md): 0.25 / 0.5 / 1 / 2 / 4 gave 684.8 / 696.8 / 699.8 / 699.4 /
    // 698.9 (asterisk-ru-f 50.6 -> 58.8 % visual groups at 1).
    float followingSilenceInSpeechCost = 1.0f;
    // Minimum durations: the segmenter's, and a fraction of the expected duration. Tuned on the
    // espeak-ng training corpus (bench/align_accuracy): fraction 0.3/0.4/0.5 gave boundary
    // p95 48.5/48.5/46.5 ms; a minimum pause of 80 ms (not 1 frame) cut missed boundaries by a
    // quarter (closures of stops at word boundaries had been taken for pauses). Retuned with the
    // real training speakers each left out of its templates (`lipsync eval --align`, visual
    // groups, klettres-en-gb / asterisk-en-allison) and the espeak-ng training corpus (p95,
    // share within 20 ms): 0.5 gave 89.3 / 55.7 %, 42.5 ms, 82.4 %; 0.6 89.3 / 56.4 %, 42.5 ms;
    // 0.7 88.8 / 56.7 %, 41.5 ms, 84.4 %; 0.8 88.2 / 55.3 %, 39.5 ms. Real voices squeezed a
    // phoneme that fits their templates poorly to its minimum and gave its frames to the
    // neighbours (festvox-ru's /l/ came out at half its length, its /r/ at twice).
    double minVowelSeconds = 0.03, minConsonantSeconds = 0.02;
    double minFractionOfExpected = 0.7;
    // The tail after the minimum (its stay probability) is set as if the minimum were this
    // fraction: the longer minimum alone made each further frame dearer, and a last phoneme held
    // long went to the filler after the line (with 0.5 here: 89.0 / 56.6 %, 40.5 ms, 84.8 %).
    double tailFractionOfExpected = 0.5;
    // The minimum follows the measured speaking rate (timeScale) up to this much slower than
    // espeak-ng's reading. The rate comes from the span of loud frames, and music or noise around
    // the line lengthens it: then minimum durations no longer fit the words into the speech, and
    // the words spill into the music. Read speech at its slowest (about 130 words a minute against
    // espeak-ng's 175) is 1.35 times slower; 1.0 lost 0.9 points within 20 ms on the training
    // corpus, 1.3 nothing.
    double minimumMaxTimeScale = 1.3;
    // A stretch no word explains (a cough, music, an added word): cost per frame.
    float fillerCostPerFrame = 1.5f;
    // After the last word: music, applause or the next sound of the show often follow a line,
    // and the last phoneme must not stretch over them. Needed since the templates were trained
    // with real speakers: a chord then sits close enough to a nasal that a final /n/ absorbed a
    // second of music at the inner filler's cost. Cheaper than that, not so cheap that dropping
    // the last words into it beats placing them (bench/align_accuracy on the training corpus:
    // p95 43.5 ms; tests/dsp/ForcedAlignerTest.cpp checks both). Two costs: straight after the
    // last phoneme, and after a pause of at least minPauseSeconds (a second filler, reached only
    // through such a pause). Without a pause, sound is more likely the last phoneme held on:
    // single words said alone end in long fricatives and vowels, which at 0.5 went to the
    // filler (klettres-en-gb, left out of its templates, aligned: 86.6 % visual groups at 0.5,
    // 88.1 % at 0.65, 89.1 % at 0.8 and 1.0; asterisk-en-allison 55.5 / 55.6 / 55.6 %).
    float edgeFillerCostPerFrame = 0.8f;
    float fillerAfterPauseCostPerFrame = 0.5f;
    float pauseCost = 3.0f;         // entering an optional pause between words
    double minPauseSeconds = 0.08;  // shortest pause between words
    float silenceLoopCost = 0.05f;  // per frame of it
    // A word the speaker left out (at most two in a row; never the word of a one-word line, whose
    // confidence alone decides: minSingleWordConfidence). 15 skipped words a real voice said
    // but the templates fit poorly (festvox-ru: "спокойным" in "Со спокойным мужеством", its
    // frames given to the words around it); on asterisk-en-allison, left out of its templates,
    // 15 / 25 / 40 gave 56.6 / 57.1 / 57.1 % aligned on the right text and 40.3 / 40.5 % on
    // another prompt's (wrong words still fall to the confidence floor); klettres-en-gb and the
    // espeak-ng training corpus unchanged.
    float skipWordCost = 25.0f;
    // ... or this much per sounded phoneme of espeak-ng's reading, whichever is more: a long word
    // the templates fit poorly is dearer to leave out than a short one (festvox-ru's 10-phoneme
    // "Покалывало" at a line's start, skipped at 25 alone, is placed). On the tune voices aligned,
    // 6 catches more bilabial closures (fillets-nl 51.5 / 56.4 -> 54.5 / 59.6 %), festvox-ru-nsh
    // misses fewer boundaries (11,201 -> 10,864; visual groups 76.9 -> 77.1 %); at 7 two short
    // words a speaker left out are squeezed in instead (AlignText test "...Skipped...").
    float skipPhonemeCost = 6.0f;
    // Saying a word another way than espeak-ng reads it (ScriptWord::alternatives): a reduction
    // must fit clearly better to be taken. See bench/align_accuracy and docs/measurements.md for
    // the tuning.
    float reductionCost = 4.0f;
    float beam = 60.0f;  // paths this much worse than the best are dropped
    int maxActiveNodes = 4000;
    // A path that fell behind the words scores best for a while (the words it has not reached
    // cost nothing yet) and then finds no way through the rest: paths on time dropped out of the
    // beam, or a window was committed to one behind, and the whole line fell to the audio alone
    // (festvox-ru's long sentences: 3 of 620 lines). Where the input's length is known, a path
    // is weighed for the beam and the commit with skipWordCost for each word still to say that
    // would not fit in the frames left at this many times the line's measured speaking rate
    // (never fewer than the words' minimum durations allow). Tune voices aligned: 0.8 / 0.9 / 1 /
    // 1.1 / 1.25 / 1.5 gave 741.35 / 742.35 / 742.40 / 740.95 / 737.75 / 736.50 against 738.25
    // with the minimum durations alone; the three lines were placed at 1 (21 of 22, 21 of 23, 17
    // of 17 words) and not at 1.5 (9 of 23, 6 of 17).
    double fastestRestRate = 1.0;
    // Bounded memory: every commitSeconds, the path up to lookaheadSeconds ago is final.
    double commitSeconds = 10, lookaheadSeconds = 4;
    // Below its floor a word counts as not placed (audio-only analysis covers it). On real
    // voices right words lie further from the templates than on espeak-ng's, and a word's
    // confidence alone tells right words from wrong ones poorly there (asterisk-en-allison,
    // each prompt against its own text and another's: area under the ROC curve 0.70; espeak-ng
    // 0.98). The median over a line's words tells a script that fits the audio from one that
    // does not far better. So the floor is minWordConfidence, but in a line whose median
    // reaches it a word needs only fittingLineShare of that median, and the word of a one-word
    // line minSingleWordConfidence. Tuned on the real training speakers, each against templates
    // trained without it (`lipsync eval --align`, visual groups, asterisk-en-allison /
    // klettres-en-gb): one floor of 0.3 gave 53.6 / 84.9 %; these floors 55.0 / 86.7 % (share
    // 0.3 / 0.5: 55.1 / 54.8 %); one floor of 0 gave 55.4 / 86.7 %, but with every prompt
    // aligned on another prompt's text it fell from 40.3 to 36.3 % (audio only: 42.4 %), where
    // these floors keep 39.3 %. Above 0.33 the share keeps an added word on espeak-ng speech
    // unplaced (tests/dsp/AlignTextTest.cpp).
    float minWordConfidence = 0.3f;
    float fittingLineShare = 0.4f;
    float minSingleWordConfidence = 0.1f;
    // A second pass on the file's own voice (alignFile): the templates moved toward the frames
    // the first pass placed (SpeakerAdaptation, a prior worth this many frames; 0: one pass),
    // the file aligned again on them. Real voices lie off templates trained on others, and their
    // boundaries with them; a few frames of the voice's own sounds bring them closer. Chosen on
    // the espeak-ng training corpus (bench/align_accuracy: 392 / 390 / 384 / 385 / 386 boundaries
    // missed at one pass / 1 / 3 / 10 / 30 frames, p95 42.5 ms throughout) and the real training
    // speakers each left out of their templates (klettres-en-gb / asterisk-en-allison, aligned
    // visual groups 89.1 / 55.6 % at one pass, 89.3 / 55.7 % at 3). Files longer than
    // fileAdaptationMaxSeconds keep one pass: the second needs every frame's features held.
    float fileAdaptationPriorFrames = 3.0f;
    double fileAdaptationMaxSeconds = 300;
    // With a speaker's adaptation carried from line to line (alignFile's `speaker`), the prior
    // of the templates the next line starts from. Chosen on the same speakers, each line
    // adapting the next (10 / 30 / 100 frames: 87.9 / 89.4 / 89.3 % and 59.3 / 59.2 / 59.3 %).
    float speakerAdaptationPriorFrames = 30.0f;
    // That carried voice also trains the set's networks further on each line's placed frames
    // (SpeakerAdaptation::learnNetworks): passes over the line, at Adam's step size (0 passes:
    // the base's networks stay). As `lipsync calibrate` trains them on its read speech. Chosen on
    // the six tune voices, each carried over its files (`lipsync eval --adapt-speaker`, summed;
    // score = visual groups + 50 jaw r + 0.5 (closures caught - false)): from the audio alone
    // 642.0 with none, 642.3 with 1 pass, 644.7 with 4; aligned 751.5, 754.9, 756.4.
    int speakerNetworkEpochs = 4;
    float speakerNetworkRate = 1e-4f;
    // How much of what the class network and the set's class bias add to the templates'
    // distances (FrameClassifier::distances() over templateDistances()) the aligner weighs too,
    // 0..1 (0: the templates alone). The network has heard far more people than the templates
    // (the `networks` speakers of config/corpus/real-speakers.txt), and with the words known it
    // still tells their sounds apart better. The words' confidences stay on the templates'
    // distances (ForcedAligner::push): on espeak-ng speech, which the templates fit better than
    // the network, the network's term lowered right words below the floor. Chosen on the six
    // voices held out for decisions, aligned (`lipsync eval --align`, summed: visual groups,
    // jaw r, closures caught, false closures): 0: 309.9, 3.84, 434.1, 59.0; 0.15: 319.9, 3.92;
    // 0.25: 326.5, 3.95, 447.1, 55.2; 0.4: 330.9, 3.96, 455.1, 55.6; 0.6: 332.3, 3.97, 452.6,
    // 55.7; 0.8: 331.9, 3.96, 451.5, 55.9. With each speaker's voice carried from line to line
    // (--adapt-speaker) 0: 325.1, 3.93, 451.3, 52.0; 0.4: 342.7, 4.01, 469.2, 52.7. On the
    // espeak-ng dev corpus (bench/align_accuracy) 0 and 0.4 alike: median 6.5 / 6.5 ms, p95
    // 35.5 / 35.5 ms, within 20 ms 85.5 / 86.2 %, words placed 665 / 666 of 672.
    float classNetworkShare = 0.4f;
};

struct AlignedWord {
    std::string text;
    double start = 0, end = 0;  // where it was placed; both 0 when skipped
    float confidence = 0;       // in [0, 1], from the two below
    float excessDb = 0;         // mean distance of its frames above the nearest class's
    float durationRatio = 0;    // its duration over the expected one
    bool placed = false;        // false: skipped, or confidence below the minimum
};

struct Alignment {
    PhonemeSchedule schedule;  // the aligned phonemes (pauses and unexplained stretches: sil)
    std::vector<AlignedWord> words;
    // Stretches no script word explains (filler: a cough, music, added words).
    std::vector<std::pair<double, double>> unexplained;
    bool complete = false;  // false: no path through the words; the caller must fall back
};

// One speaker's own class means: the templates moved toward frames of that speaker whose classes
// are known (a confident alignment). Each frame counts for the nearest template of its class,
// and each template heard becomes (τ·t + Σx) / (τ + n) over its n frames: the maximum a
// posteriori estimate of a mean under a prior worth τ frames (Gauvain & Lee 1994). Frames at a
// segment's edges are left out: they straddle two sounds. Frames are assigned against the base
// set, so what is added does not depend on what was added before. With learnNetworks, each
// utterance also trains the set's class and jaw networks further (those do depend on the order).
class SpeakerAdaptation {
  public:
    explicit SpeakerAdaptation(TemplateSet base);
    // Frames of one utterance (times ascending) and its segments. Silence is not learnt, nor
    // frames `silent` marks (non-zero: below the energy gate, such as a stop's closure, whose
    // spectrum is the room's); `silent` is empty or has one value a frame.
    void add(std::span<const FrameFeatures> frames, const PhonemeSchedule& segments,
             std::span<const std::uint8_t> silent = {});
    void add(const SpeakerAdaptation& other);  // another's frames (the same base set)
    // From now on each utterance added also trains the set's networks further on its frames
    // (TemplateTrainer::fineTuneNetworks: `epochs` passes at Adam step `rate`), from where the
    // utterances before left them; adapted() carries them. 0 passes: the base's networks stay.
    void learnNetworks(int epochs, float rate);
    // The base set with every template heard moved, under a prior worth `priorFrames` frames.
    TemplateSet adapted(float priorFrames) const;
    // adapted() once any frame has been learnt; before that nothing (the base serves as it is).
    std::optional<TemplateSet> adaptedIfHeard(float priorFrames) const;
    std::size_t frames() const { return frames_; }                         // frames learnt so far
    bool networksTrained() const { return classNetwork_ || jawNetwork_; }  // learnNetworks did
    const TemplateSet& base() const { return base_; }
    // What has been learnt, kept in a file across runs (lipsyncd's speaker_file): the templates
    // heard and the networks trained further, with a fingerprint of the base set. save() writes
    // FILE.tmp and renames it over FILE, so a crash leaves the last good file. load() replaces what
    // has been learnt; InputError naming the file and field when it is not such a file or was
    // learnt on another base set (what had been learnt stays).
    void save(const std::filesystem::path& file) const;
    void load(const std::filesystem::path& file);

  private:
    std::size_t nearestOfClass(std::span<const float> x, std::size_t cls,
                               std::vector<double>& distances) const;
    void trainNetworks(std::span<const FrameFeatures> frames, const PhonemeSchedule& segments);

    TemplateSet base_;
    std::shared_ptr<const FeatureWeighting> weighting_;  // the classifier's distance
    int networkEpochs_ = 0;
    float networkRate_ = 1e-4f;
    std::optional<ClassNetwork> classNetwork_;  // trained further on the utterances (learnNetworks)
    std::optional<JawNetwork> jawNetwork_;
    // The base, weighted: per class, [feature][template of the class], so that one feature
    // serves every template of the class at once.
    std::vector<float> weighted_;
    std::vector<std::size_t> classStart_;  // per class of base_, and one past: first template
    std::vector<double> sums_;             // [template][feature]
    std::vector<double> counts_;           // [template]
    std::size_t frames_ = 0;
};

// A voice to carry from line to line (the service's show voice, `eval --adapt-speaker`, `align
// --speaker`): nothing heard yet, and each line added trains its networks further as `config`
// says (AlignerConfig::speakerNetworkEpochs, speakerNetworkRate).
SpeakerAdaptation carriedVoice(TemplateSet base, const AlignerConfig& config);

// Frame-synchronous Viterbi over the script's phonemes (a chain of minimum-duration states and
// a geometric tail per phoneme: Rabiner 1989, section IV.D), with an optional pause and an
// optional filler between words and word skips, beam-pruned; the path is committed in windows
// (partial traceback) so memory is bounded by the window and the script, not the audio.
class ForcedAligner {
  public:
    // timeScale: audio durations / synthesiser durations (speech rate), e.g. from
    // measureSpeechTiming(); hopSeconds: the frame hop.
    ForcedAligner(std::span<const ScriptWord> script, const PhonemeSet& set, double hopSeconds,
                  double timeScale = 1.0, const AlignerConfig& config = {});
    ForcedAligner(ForcedAligner&&) noexcept;
    ForcedAligner& operator=(ForcedAligner&&) noexcept;
    ~ForcedAligner();

    // One frame: its centre time, the classifier's distance to each class (+inf: no template
    // or no spectrum) and whether it is below the energy gate. `confidenceDistances`, when not
    // empty, are what the words' confidences are measured on instead (the templates' own, when
    // `distances` carry the class network's share: its term lowered right words' confidence on
    // voices it fits less well than the templates do, and left them unplaced).
    void push(double time, std::span<const float> distances, bool silent,
              std::span<const float> confidenceDistances = {});
    // The input's length in frames, when known before the end (a file). The path is committed
    // in windows, each time from the best partial path; knowing the length, a commit passes
    // over partial paths that can no longer fit the rest of the words in the frames left. A
    // slow speaker's file otherwise could commit to a path that fell behind the words and find
    // no way through them at the end.
    void expectFrames(std::int64_t total);
    Alignment finish();
    // Following a line as it is said (LineFollower), before the first push(): the path is
    // not kept (finish() then places no word) and the room for the windows of the config's
    // lookaheadSeconds and commitSeconds is reserved now, so push() never allocates.
    void followOnly();
    // The phonemes (indices into the set) the best partial path so far holds, out[k] in the
    // frame k before the newest (at most lookaheadSeconds back): a pause between words is
    // silence; -1 in a stretch no word explains (a filler) and before the first frame.
    void phonemesBack(std::span<int> out) const;
    // The shortest audio the script fits in (minimum durations), seconds.
    double minimumSeconds() const;
    // Largest number of frames of back-pointers held at once (the memory bound, for tests).
    std::size_t peakFramesHeld() const;

  private:
    struct State;
    std::unique_ptr<State> state_;
};

struct AlignFileResult {
    PhonemeSchedule schedule;   // aligned where words were placed, audio-only elsewhere
    PhonemeSchedule audioOnly;  // the front end's own schedule (analyzeFile)
    // Every frame: its RMS level (dBFS) and the jaw heard; aligned unless fellBack.
    LevelTrack levels;
    Alignment alignment;
    double durationSeconds = 0, timeScale = 1;
    std::vector<std::string> warnings;  // unplaced words, fallbacks: for the user
    bool fellBack = false;              // the whole file is audio-only analysis
};

struct SpeechTiming {
    // The speech found in the file against the synthesiser's durations of the script: how
    // much slower (> 1) the speaker is; 1 when the file has no speech.
    double timeScale = 1;
    double durationSeconds = 0;  // the whole file's
};

// One quick pass over the file's levels, before the alignment.
SpeechTiming measureSpeechTiming(std::span<const ScriptWord> script,
                                 const std::filesystem::path& file,
                                 const DecodeOptions& decode = {},
                                 const std::optional<RawFormat>& raw = std::nullopt);

// Aligns the script on a file, with the audio-only schedule in the stretches the script does
// not explain and for words not placed. Bad audio (no speech, far too short for the words)
// gives a flagged audio-only result, not an error. `raw` input is read once (no time scale).
// Aligned twice (AlignerConfig::fileAdaptationPriorFrames): the second time on templates moved
// toward the file's own voice, keeping the first pass's verdict on which words were placed.
// `speaker`, when given, carries one speaker's voice from line to line: the file starts from its
// templates (its base set, not `templates`) and its placed frames are added to it afterwards.
AlignFileResult alignFile(const std::filesystem::path& file, std::span<const ScriptWord> script,
                          const TemplateSet& templates, const PhonemeSet& set,
                          const FrontEndConfig& config = {}, const AlignerConfig& aligner = {},
                          const DecodeOptions& decode = {},
                          const std::optional<RawFormat>& raw = std::nullopt,
                          SpeakerAdaptation* speaker = nullptr);

// A line whose words are known, followed as it is said (the service's live lines after a cue):
// a fixed-lag forced alignment. Each frame's class is the one the best partial path held `lag`
// frames after it (ForcedAligner::phonemesBack); where no word explains the sound (a cough, an
// added word) it is the front end's own class for the frame. The speaking rate is unknown while
// the line is said: the synthesiser's durations are taken as they are (time scale 1).
class LineFollower {
  public:
    using SegmentSink = std::function<void(const PhonemeSegment&)>;
    // The window is committed every kCommitSeconds (AlignerConfig::lookaheadSeconds still
    // bounds how far back a path may change): the room reserved for it stays small.
    static constexpr double kCommitSeconds = 1.0;
    // `lagSeconds`: from 0 to the config's lookaheadSeconds.
    LineFollower(std::span<const ScriptWord> script, const PhonemeSet& set, double hopSeconds,
                 double lagSeconds, const AlignerConfig& config = {});
    // Each segment as it closes (the set's names; frames cover their hop around their time).
    void onSegment(SegmentSink sink) { sink_ = std::move(sink); }
    // One frame of the front end, from inside StreamingAnalyzer's frame sink: its label,
    // templateDistances() and distances(). Allocates nothing.
    void push(const FrameLabel& label, std::span<const float> templateDistances,
              std::span<const float> distances);
    // The phoneme of the segment still open (-1: none yet) and the end of its newest frame.
    int openPhoneme() const { return open_.phoneme; }
    double openUntil() const { return open_.end; }
    // What the best path so far goes on to after the open phoneme, among the frames not
    // decided yet (-1: nothing else yet), and where it begins: a guess the lag may still change.
    int upcomingPhoneme() const { return upcoming_.phoneme; }
    double upcomingStart() const { return upcoming_.start; }
    // The line is over: the frames held back go to the best path's ends, and the open segment
    // closes.
    void finish();
    int lagFrames() const { return lag_; }

  private:
    struct Held {
        double time = 0;
        int heard = 0;  // the front end's own class
    };
    void place(int back);
    const Held& heldBack(int back) const;
    int classBack(int back) const;

    const PhonemeSet* set_;
    ForcedAligner aligner_;
    double hop_;
    int lag_;
    float share_;
    std::vector<float> term_, mixed_;
    std::vector<Held> held_;  // the last lag_ + 1 frames, a ring
    std::vector<int> path_;   // the best path's phonemes back from the newest frame
    std::int64_t frames_ = 0;
    struct Open {
        int phoneme = -1;
        double start = 0, end = 0;
    } open_, upcoming_;
    SegmentSink sink_;
};

// A file followed as a live line is (LineFollower over the streaming front end), for `lipsync
// eval --follow-lag`: the schedule and the levels (heard jaw at the audio-only share) the
// service's live mouth takes from a line with its words.
AnalysisResult followFile(const std::filesystem::path& file, std::span<const ScriptWord> script,
                          const TemplateSet& templates, const PhonemeSet& set, double lagSeconds,
                          const FrontEndConfig& config = {}, const AlignerConfig& aligner = {},
                          const DecodeOptions& decode = {});

}  // namespace lipsyncd::dsp
