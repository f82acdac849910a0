#include "AlignmentGraph.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

namespace lipsyncd::dsp {

namespace {

// At most this many words in a row may be skipped (each at its own cost: wordSkipCost).
constexpr int kMaxSkippedInARow = 2;
// The tail's stay probability is kept in this range: a phoneme may always end, and always stay.
constexpr double kMinStay = 0.05, kMaxStay = 0.97;

class GraphBuilder {
  public:
    GraphBuilder(const PhonemeSet& set, double hop, double scale, const AlignerConfig& c)
        : set_(set), hop_(hop), scale_(scale), config_(c) {}

    AlignmentGraph build(std::span<const ScriptWord> script) {
        graph_.words = static_cast<int>(script.size());
        // A one-word line's word is never skipped: its confidence alone says whether it was
        // said (AlignerConfig::minSingleWordConfidence). Skipped, the whole line was filler and
        // its word got no confidence at all; ktuberling's children lost four words that way.
        maxSkipped_ = script.size() == 1 ? 0 : kMaxSkippedInARow;
        add({AlignmentNode::Kind::Start});
        units_.push_back({0});
        addGap(0);
        for (std::size_t w = 0; w < script.size(); ++w) {
            addWord(script[w], static_cast<int>(w));
            addGap(static_cast<int>(w) + 1);
        }
        flatten();
        return std::move(graph_);
    }

  private:
    int add(AlignmentNode node) {
        graph_.nodes.push_back(node);
        incoming_.emplace_back();
        return static_cast<int>(graph_.nodes.size()) - 1;
    }
    void edge(int from, int to, float cost, bool skips = false) {
        incoming_[to].push_back({from, cost, skips});
    }

    // Edges into `to` from the end of the unit before it, and, skipping words, from earlier.
    void fromPreviousUnits(int to, std::size_t unit, float cost) {
        for (int skipped = 0; skipped <= maxSkipped_ && skipped < static_cast<int>(unit); ++skipped)
            for (int from : units_[unit - 1 - skipped])
                edge(from, to, cost + skipCost(static_cast<int>(unit) - 1 - skipped, skipped),
                     skipped > 0);
    }

    // The pause and filler before word `gap` (after the last word when gap == words).
    void addGap(int gap) {
        // Silence before and after the words is expected; between them it costs, and it lasts:
        // a stop's closure at a word boundary is silent too, but short, and part of the stop.
        const bool inner = gap > 0 && gap < graph_.words;
        AlignmentNode pause{AlignmentNode::Kind::Pause};
        pause.phoneme = static_cast<int>(set_.silence());
        pause.word = gap;
        AlignmentNode filler{AlignmentNode::Kind::Filler};
        filler.word = gap;
        filler.loopCost = 0;  // its cost is per frame, in the emission
        const bool after = gap == graph_.words;
        filler.frameCost = after ? config_.edgeFillerCostPerFrame : config_.fillerCostPerFrame;
        const auto [first, last] = addChainOf(pause, inner ? minPauseFrames() : 1);
        graph_.nodes[last].loopCost = config_.silenceLoopCost;
        const int f = add(filler);
        // The unit a gap ends is the word before it (or the start): both join it.
        const std::size_t unit = units_.size() - 1;
        for (int node : {first, f}) {
            const float enter = node == first && inner ? config_.pauseCost : 0.0f;
            for (int from : units_[unit]) edge(from, node, enter);
            for (int s = 1; s <= maxSkipped_ && s <= static_cast<int>(unit); ++s)
                for (int from : units_[unit - s])  // the words between skipped
                    edge(from, node, enter + skipCost(static_cast<int>(unit) - s, s), true);
        }
        edge(last, f, 0);  // a pause, then something else; edges only go forward
        const int afterPause = after ? addFillerAfterPause(units_[unit], pause, filler) : -1;
        units_.back().push_back(last);
        units_.back().push_back(f);
        if (afterPause >= 0) units_.back().push_back(afterPause);
    }

    int minPauseFrames() const {
        return std::max(1, static_cast<int>(std::lround(config_.minPauseSeconds / hop_)));
    }

    // `frames` copies of `node` in a row, each entered from the one before: {first, last}.
    std::pair<int, int> addChainOf(const AlignmentNode& node, int frames) {
        const int first = add(node);
        int last = first;
        for (int k = 1; k < frames; ++k) {
            const int n = add(node);
            edge(last, n, 0);
            last = n;
        }
        return {first, last};
    }

    // After the last word, sound straight after its last phoneme is more likely that phoneme
    // going on (a final fricative or vowel held long) than something else, but after a pause
    // of at least minPauseSeconds, something else (music, the next sound of the show) is
    // likelier: a second filler, cheaper per frame, entered only through such a pause. Returns
    // that filler's node.
    int addFillerAfterPause(const std::vector<int>& wordEnds, const AlignmentNode& pause,
                            AlignmentNode filler) {
        AlignmentNode silent = pause;
        silent.silentOnly = true;  // a pause heard, not a quiet end of the phoneme taken for one
        const auto [first, last] = addChainOf(silent, minPauseFrames());
        for (int from : wordEnds) edge(from, first, 0);
        filler.frameCost = config_.fillerAfterPauseCostPerFrame;
        const int f = add(filler);
        edge(last, f, 0);
        return f;
    }

    // A word: a chain per pronunciation, side by side (each entered from the unit before and
    // left into the unit after); the first pronunciation sets the expected duration.
    void addWord(const ScriptWord& word, int w) {
        const double before = graph_.expectedSeconds;
        const std::size_t unit = units_.size();
        std::vector<int> lasts;
        int shortest = std::numeric_limits<int>::max();
        int sounded = 0;  // phones of espeak-ng's own reading
        for (std::size_t k = 0; k <= word.alternatives.size(); ++k) {
            const auto& phonemes = k == 0 ? word.phonemes : word.alternatives[k - 1];
            int frames = 0;
            const int phonesBefore = graph_.phones;
            const int last = addChain(word.text, phonemes, w, unit, k == 0, frames);
            if (k == 0) sounded = graph_.phones - phonesBefore;
            if (last < 0) {
                if (k == 0) throw InputError("word '" + word.text + "' has no phonemes to align");
                continue;  // an alternative of silence only: nothing to add
            }
            lasts.push_back(last);
            shortest = std::min(shortest, frames);
        }
        graph_.minimumFrames += shortest;
        wordSkipCost_.push_back(wordSkipCost(sounded));
        units_.push_back(lasts);
        graph_.wordExpectedSeconds.push_back(graph_.expectedSeconds - before);
    }

    // One pronunciation's chain; returns its last node (-1: no sounds), `frames` its minimum.
    // `expected`: espeak-ng's own reading; another (a reduction) costs reductionCost to enter.
    int addChain(const std::string& text, const PhonemeSchedule& phonemes, int w, std::size_t unit,
                 bool expected, int& frames) {
        int previous = -1;
        for (const auto& seg : phonemes) {
            const auto idx = set_.find(seg.phoneme);
            if (!idx)
                throw InputError("word '" + text + "': phoneme '" + seg.phoneme +
                                 "' is not in the phoneme set");
            if (*idx == set_.silence()) continue;  // pauses are the gaps' job
            // The phoneme's duration in frames at a speaking rate (at least one frame).
            const auto framesAt = [&](double scale) {
                return std::max(hop_, seg.duration() * scale) / hop_;
            };
            const double expectedFrames = framesAt(scale_);
            if (expected) graph_.expectedSeconds += expectedFrames * hop_;
            const double classMin =
                (set_[*idx].vowel ? config_.minVowelSeconds : config_.minConsonantSeconds) / hop_;
            const double minimumFrames = framesAt(std::min(scale_, config_.minimumMaxTimeScale));
            const int chain =
                std::max(1, static_cast<int>(std::lround(std::max(
                                classMin, config_.minFractionOfExpected * minimumFrames))));
            frames += chain;
            const double tailFrom = std::max(1.0, config_.tailFractionOfExpected * expectedFrames);
            const double stay = std::clamp(1.0 - 1.0 / std::max(1.0, expectedFrames - tailFrom + 1),
                                           kMinStay, kMaxStay);
            for (int k = 0; k < chain; ++k) {
                AlignmentNode node;
                node.phoneme = static_cast<int>(*idx);
                node.word = w;
                node.phone = graph_.phones;
                if (k + 1 == chain) {
                    node.loopCost = static_cast<float>(-std::log(stay));
                    node.exitCost = static_cast<float>(-std::log(1 - stay));
                }
                const int n = add(node);
                if (previous >= 0)
                    edge(previous, n, 0);
                else
                    fromPreviousUnits(n, unit, expected ? 0.0f : config_.reductionCost);
                previous = n;
            }
            ++graph_.phones;
        }
        return previous;
    }

    void flatten() {
        const int n = static_cast<int>(graph_.nodes.size());
        graph_.reach.assign(n, 0);
        graph_.endCost.assign(n, kNever);
        for (int to = 0; to < n; ++to) {
            auto& node = graph_.nodes[to];
            node.firstEdge = static_cast<int>(graph_.edges.size());
            node.edgeCount = static_cast<int>(incoming_[to].size());
            for (const auto& e : incoming_[to]) {
                graph_.edges.push_back(e);
                graph_.reach[e.from] = std::max(graph_.reach[e.from], to);
            }
        }
        for (int i = 0; i < n; ++i) {
            graph_.reach[i] = std::max(graph_.reach[i], i);
            if (i > 0) graph_.reach[i] = std::max(graph_.reach[i], graph_.reach[i - 1]);
        }
        // Ending: after the last word, or with the last words skipped.
        const std::size_t last = units_.size() - 1;
        for (int s = 0; s <= maxSkipped_ && s < static_cast<int>(last) + 1; ++s)
            for (int node : units_[last - s])
                if (graph_.nodes[node].kind != AlignmentNode::Kind::Start)
                    graph_.endCost[node] =
                        std::min(graph_.endCost[node], skipCost(static_cast<int>(last) - s, s));
        countFramesToEnd();
    }

    // Backwards over the nodes (every edge goes forward): a node's successors are done first.
    // A path ends having said every word in the last word's unit (its end, the gap after it).
    void countFramesToEnd() {
        const int n = static_cast<int>(graph_.nodes.size());
        constexpr int kUnreachable = std::numeric_limits<int>::max() / 2;
        graph_.framesToEnd.assign(n, kUnreachable);
        for (int node : units_.back()) graph_.framesToEnd[node] = 0;
        for (int to = n - 1; to >= 0; --to) {
            const auto& node = graph_.nodes[to];
            for (int e = node.firstEdge; e < node.firstEdge + node.edgeCount; ++e) {
                if (graph_.edges[e].skips) continue;
                auto& from = graph_.framesToEnd[graph_.edges[e].from];
                from = std::min(from, graph_.framesToEnd[to] + 1);
            }
        }
    }

    // Skipping `count` words from word `first` on.
    float skipCost(int first, int count) const {
        float sum = 0;
        for (int w = first; w < first + count; ++w) sum += wordSkipCost_[w];
        return sum;
    }

    // A long word left out is a long stretch of the speaker's sound given to the words around
    // it; a short one may be said so fast that it leaves no trace (AlignerConfig::skipPhonemeCost).
    // `sounded`: the word's phonemes other than silence in espeak-ng's reading.
    float wordSkipCost(int sounded) const {
        return std::max(config_.skipWordCost,
                        config_.skipPhonemeCost * static_cast<float>(sounded));
    }

    std::vector<float> wordSkipCost_;  // per word, in script order
    const PhonemeSet& set_;
    double hop_, scale_;
    AlignerConfig config_;
    int maxSkipped_ = kMaxSkippedInARow;  // words skipped in a row, at most
    AlignmentGraph graph_;
    std::vector<std::vector<AlignmentEdge>> incoming_;
    // Per unit (the start, then each word) the nodes a path leaves it from: the word's last
    // node and the pause and filler after it.
    std::vector<std::vector<int>> units_;
};

}  // namespace

AlignmentGraph AlignmentGraph::build(std::span<const ScriptWord> script, const PhonemeSet& set,
                                     double hopSeconds, double timeScale,
                                     const AlignerConfig& config) {
    if (script.empty()) throw InputError("forced alignment: no words to align");
    if (!(hopSeconds > 0) || !(timeScale > 0) || !std::isfinite(timeScale))
        throw InputError("forced alignment: hop and time scale must be positive");
    return GraphBuilder(set, hopSeconds, timeScale, config).build(script);
}

}  // namespace lipsyncd::dsp
