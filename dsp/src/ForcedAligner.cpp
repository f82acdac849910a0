// Forced alignment by frame-synchronous Viterbi on the classifier's distances (the templates'
// distances read as negative log-likelihoods: Rabiner 1989, section III.B; alignFile adds a share
// of the class network's scaled likelihoods, Bourlard & Morgan 1994), beam-pruned, with
// the path committed in windows: every commitSeconds, the best path is traced back and the
// part older than lookaheadSeconds becomes final; paths that disagree with it there are
// dropped, so what was committed is never contradicted later. Following a line as it is said
// (followOnly, LineFollower), nothing of the path is kept: the windows only bound the memory,
// which is reserved up front, and phonemesBack() reads the best partial path back from the
// newest frame.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>

#include "AlignmentGraph.hpp"
#include "AlignmentPath.hpp"
#include "AlignmentSweep.hpp"

namespace lipsyncd::dsp {

namespace {
// A class without a template (distance +inf) costs as much as one this far off (dB).
constexpr float kMissingClassDb = 12.0f;
// In a frame below the energy gate, speech classes count as this much further off (dB).
constexpr float kSilentExcessDb = 3.0f;
// The input's expected length in frames is the file's duration over the hop: the analyser's
// count can differ by its edge frames.
constexpr std::int64_t kFrameSlack = 2;

// The first node of [from, to] with the least cost (-1: none finite), as a scan keeping the
// first strictly lower value finds it: four such scans side by side, over every fourth node,
// then the least of their four (the first node on a tie).
using Costs4 = float __attribute__((vector_size(4 * sizeof(float))));
using Nodes4 = int __attribute__((vector_size(4 * sizeof(int))));

int firstBest(std::span<const float> cost, int from, int to) {
    Costs4 least = kNever - Costs4{};
    Nodes4 at = -1 - Nodes4{}, node = from + Nodes4{0, 1, 2, 3};
    int n = from;
    for (; n + 3 <= to; n += 4, node += 4) {
        Costs4 v;
        std::memcpy(&v, &cost[n], sizeof v);
        const Nodes4 lower = v < least;
        least = lower ? v : least;
        at = lower ? node : at;
    }
    int first = -1;
    float best = kNever;
    for (int k = 0; k < 4; ++k)
        if (least[k] < best || (least[k] == best && at[k] >= 0 && at[k] < first))
            best = least[k], first = at[k];
    for (; n <= to; ++n)  // the last few, after every node above
        if (cost[n] < best) best = cost[n], first = n;
    return first;
}
}  // namespace

struct ForcedAligner::State {
    State(std::span<const ScriptWord> script, const PhonemeSet& s, double hopSeconds,
          double timeScale, const AlignerConfig& c)
        : graph(AlignmentGraph::build(script, s, hopSeconds, timeScale, c)),
          set(&s),
          hop(hopSeconds),
          config(c),
          path(script, graph, s, hopSeconds, c),
          sweep(graph, s.size()) {
        const auto n = graph.nodes.size();
        delta.assign(n, kNever);
        next.assign(n, kNever);
        owed.assign(n, kNever);
        arg.assign(n, -1);
        delta[0] = 0;  // the start node, before the first frame
        // The frames a word still to say takes at the fastest rate allowed for the rest of the
        // line: the shortest path's frames, stretched to that rate (never below the shortest;
        // a rate of 0 or less: the shortest alone).
        if (graph.minimumFrames > 0 && graph.words > 0) {
            const double expected = graph.expectedSeconds / hopSeconds;
            if (c.fastestRestRate > 0)
                restStretch = std::max(1.0, expected / c.fastestRestRate / graph.minimumFrames);
            framesPerWord = restStretch * std::max(1.0, double(graph.minimumFrames) / graph.words);
        }
    }

    // Per-frame data the window keeps: back-pointers for the active nodes, and the excess
    // distances for the word confidences.
    struct Row {
        double time;
        int lo, count;
        std::size_t back, excess;  // offsets into back_, excess_
    };

    void scoreFrame(std::span<const float> distances, std::span<const float> confidenceDistances,
                    bool silent, std::vector<float>& excess);
    void step();
    int ancestor(std::int64_t frame, int node, std::int64_t atFrame) const;
    void ancestors(std::int64_t frame, std::span<int> nodes, std::int64_t atFrame) const;
    void commit(std::int64_t keepFrames);
    int commitFrom() const;
    float behindCost(int node, double framesLeft) const;
    void emitPath(std::int64_t lastFrame, int node);
    void dropFront(std::int64_t frames);

    AlignmentGraph graph;
    const PhonemeSet* set;
    double hop;
    AlignerConfig config;
    AlignmentPath path;
    AlignmentSweep sweep;
    std::vector<float> delta, next;  // per node: cost of the best path there, last frame and this
    std::vector<float> owed;         // step(): next plus behindCost, where the length is known
    std::vector<std::int32_t> arg;   // per node: where its best path came from this frame
    std::vector<int> alive, traced;  // commit(): the active nodes, and where their paths were
    int lo = 0, hi = 0;              // active nodes after the last frame
    std::vector<Row> rows;
    std::vector<std::int32_t> back;
    std::vector<float> excess;
    std::int64_t windowStart = 0, frames = 0;
    std::int64_t totalFrames = -1;  // the input's length, when known (expectFrames)
    std::size_t peakRows = 0;
    bool finished = false;
    bool keepPath = true;                       // false: following (followOnly)
    std::vector<int> nodes;                     // emitPath(): the path's node per frame
    double restStretch = 1, framesPerWord = 1;  // behindCost()
};

namespace {
// The least finite distance of a frame (kNever: none).
float nearestOf(std::span<const float> distances, std::size_t classes) {
    float nearest = kNever;
    for (std::size_t c = 0; c < classes && c < distances.size(); ++c)
        if (std::isfinite(distances[c])) nearest = std::min(nearest, distances[c]);
    return nearest;
}

// How far a class lies beyond the nearest (kMissingClassDb for one without a distance).
float excessOf(std::span<const float> distances, std::size_t c, float nearest) {
    if (!std::isfinite(nearest)) return 0;
    const float d = c < distances.size() ? distances[c] : kNever;
    return std::isfinite(d) ? d - nearest : kMissingClassDb;
}
}  // namespace

void ForcedAligner::State::scoreFrame(std::span<const float> distances,
                                      std::span<const float> confidenceDistances, bool silent,
                                      std::vector<float>& excessOut) {
    const auto emission = sweep.classCosts();
    const std::size_t classes = set->size();
    if (confidenceDistances.empty()) confidenceDistances = distances;
    const float nearest = nearestOf(distances, classes);
    const float nearestForConfidence = nearestOf(confidenceDistances, classes);
    const auto sil = set->silence();
    for (std::size_t c = 0; c < classes; ++c) {
        const float ex = excessOf(distances, c, nearest);
        float shown = excessOf(confidenceDistances, c, nearestForConfidence);
        float cost = config.distanceWeight * ex * (ex + 2 * (std::isfinite(nearest) ? nearest : 0));
        if (silent || !std::isfinite(nearest)) {  // below the gate, or no spectrum at all
            if (c == sil) {
                cost = shown = 0;
            } else {
                cost +=
                    (*set)[c].vowel ? config.speechInSilenceCost : config.consonantInSilenceCost;
                shown += kSilentExcessDb;
            }
        } else if (c == sil) {
            cost += config.silenceInSpeechCost;
        }
        emission[c] = cost;
        excessOut.push_back(shown);
    }
    sweep.setSilent(silent);
}

void ForcedAligner::State::step() {
    const int from = lo, to = graph.reach[hi];
    sweep.relax(delta, lo, hi, from, to, next, arg);
    // The beam ranks the paths by what each owes for having fallen behind the words too, so a
    // path on time stays beside one behind that scores best for now (behindCost).
    std::span<const float> ranked = next;
    if (totalFrames >= 0) {
        const double left = std::max(0.0, double(totalFrames - frames - 1));
        for (int n = from; n <= to; ++n)
            owed[n] = next[n] < kNever ? next[n] + behindCost(n, left) : kNever;
        ranked = owed;
    }
    const int bestNode = firstBest(ranked, from, to);
    // Pause and filler nodes loop at a finite cost, so some node is always reachable.
    if (bestNode < 0) throw std::logic_error("forced alignment: no node reachable");
    // Keep what lies within the beam, and at most maxActiveNodes around the best: a select per
    // node (a branch on the beam would be mispredicted often), then the kept range's ends.
    const int half = std::max(1, config.maxActiveNodes / 2);
    const int keepLo = std::max(from, bestNode - half), keepHi = std::min(to, bestNode + half);
    const float bound = ranked[bestNode] + config.beam;
    for (int n = from; n < keepLo; ++n) delta[n] = kNever;
    for (int n = keepLo; n <= keepHi; ++n) delta[n] = ranked[n] <= bound ? next[n] : kNever;
    for (int n = keepHi + 1; n <= to; ++n) delta[n] = kNever;
    int newLo = from, newHi = to;  // the best node is kept: both scans stop
    while (!(delta[newLo] < kNever)) ++newLo;
    while (!(delta[newHi] < kNever)) --newHi;
    // Only the kept nodes' back-pointers can be followed later.
    back.insert(back.end(), arg.begin() + newLo, arg.begin() + newHi + 1);
    rows.back().lo = newLo;
    rows.back().count = newHi - newLo + 1;
    lo = newLo;
    hi = newHi;
}

// The node a path in `node` at `frame` passed through at `atFrame` (≤ frame, in the window).
int ForcedAligner::State::ancestor(std::int64_t frame, int node, std::int64_t atFrame) const {
    ancestors(frame, std::span(&node, 1), atFrame);
    return node;
}

// ancestor() for many nodes at once, in place: walked back together, a frame at a time (one
// path's walk alone is a chain of dependent loads).
void ForcedAligner::State::ancestors(std::int64_t frame, std::span<int> nodes,
                                     std::int64_t atFrame) const {
    for (std::int64_t f = frame; f > atFrame; --f) {
        const auto& row = rows[static_cast<std::size_t>(f - windowStart)];
        for (auto& node : nodes) node = back[row.back + static_cast<std::size_t>(node - row.lo)];
    }
}

void ForcedAligner::State::emitPath(std::int64_t lastFrame, int node) {
    nodes.resize(static_cast<std::size_t>(lastFrame - windowStart + 1));
    for (std::int64_t f = lastFrame; f >= windowStart; --f) {
        nodes[static_cast<std::size_t>(f - windowStart)] = node;
        if (f > windowStart) node = ancestor(f, node, f - 1);
    }
    const std::size_t classes = set->size();
    for (std::size_t i = 0; i < nodes.size(); ++i) {
        const auto& row = rows[i];
        path.add(row.time, nodes[i], std::span<const float>(excess).subspan(row.excess, classes));
    }
}

void ForcedAligner::State::dropFront(std::int64_t count) {
    const auto n = static_cast<std::size_t>(count);
    if (n >= rows.size()) {
        rows.clear();
        back.clear();
        excess.clear();
    } else {
        const auto b = rows[n].back, e = rows[n].excess;
        rows.erase(rows.begin(), rows.begin() + static_cast<std::ptrdiff_t>(n));
        back.erase(back.begin(), back.begin() + static_cast<std::ptrdiff_t>(b));
        excess.erase(excess.begin(), excess.begin() + static_cast<std::ptrdiff_t>(e));
        for (auto& r : rows) {
            r.back -= b;
            r.excess -= e;
        }
    }
    windowStart += count;
}

// What a path in `node` owes for having fallen behind the words (AlignerConfig::
// fastestRestRate): skipWordCost for each word still to say that would not fit in the frames
// left at that rate. Nothing while the input's length is unknown (a followed line).
float ForcedAligner::State::behindCost(int node, double framesLeft) const {
    if (totalFrames < 0) return 0;
    const double over = restStretch * graph.framesToEnd[node] - framesLeft - kFrameSlack;
    return over > 0 ? config.skipWordCost * float(std::ceil(over / framesPerWord)) : 0.0f;
}

// The partial path to commit to: the best, counting against each what it owes for having
// fallen behind the words.
int ForcedAligner::State::commitFrom() const {
    const double left = totalFrames > frames ? double(totalFrames - frames) : 0.0;
    int best = lo;
    float bestScore = kNever;
    for (int n = lo; n <= hi; ++n) {
        if (!(delta[n] < kNever)) continue;
        const float score = delta[n] + behindCost(n, left);
        if (score < bestScore) {
            bestScore = score;
            best = n;
        }
    }
    return best;
}

void ForcedAligner::State::commit(std::int64_t keepFrames) {
    const std::int64_t last = frames - 1, upTo = last - keepFrames;
    if (upTo < windowStart) return;
    const int bestNode = commitFrom();
    const int anchor = ancestor(last, bestNode, upTo);
    if (keepPath) emitPath(upTo, anchor);
    alive.clear();
    for (int n = lo; n <= hi; ++n)
        if (delta[n] < kNever) alive.push_back(n);
    traced = alive;
    ancestors(last, traced, upTo);
    for (std::size_t i = 0; i < alive.size(); ++i)
        if (traced[i] != anchor) delta[alive[i]] = kNever;
    while (lo < hi && !(delta[lo] < kNever)) ++lo;
    while (hi > lo && !(delta[hi] < kNever)) --hi;
    dropFront(upTo - windowStart + 1);
}

ForcedAligner::ForcedAligner(std::span<const ScriptWord> script, const PhonemeSet& set,
                             double hopSeconds, double timeScale, const AlignerConfig& config)
    : state_(std::make_unique<State>(script, set, hopSeconds, timeScale, config)) {}
ForcedAligner::ForcedAligner(ForcedAligner&&) noexcept = default;
ForcedAligner& ForcedAligner::operator=(ForcedAligner&&) noexcept = default;
ForcedAligner::~ForcedAligner() = default;

void ForcedAligner::push(double time, std::span<const float> distances, bool silent,
                         std::span<const float> confidenceDistances) {
    auto& s = *state_;
    if (s.finished) throw std::logic_error("ForcedAligner::push after finish");
    s.rows.push_back({time, 0, 0, s.back.size(), s.excess.size()});
    s.scoreFrame(distances, confidenceDistances, silent, s.excess);
    s.step();
    ++s.frames;
    s.peakRows = std::max(s.peakRows, s.rows.size());
    const auto keep = static_cast<std::int64_t>(std::lround(s.config.lookaheadSeconds / s.hop));
    const auto every = static_cast<std::int64_t>(std::lround(s.config.commitSeconds / s.hop));
    if (static_cast<std::int64_t>(s.rows.size()) >= keep + std::max<std::int64_t>(1, every))
        s.commit(keep);
}

void ForcedAligner::expectFrames(std::int64_t total) {
    state_->totalFrames = total;
}

Alignment ForcedAligner::finish() {
    auto& s = *state_;
    s.finished = true;
    if (s.frames == 0) return s.path.finish(false);
    int endNode = -1, bestNode = s.lo;
    float endBest = kNever;
    for (int n = s.lo; n <= s.hi; ++n) {
        if (s.delta[n] < s.delta[bestNode]) bestNode = n;
        const float v = s.delta[n] + s.graph.endCost[n];
        if (v < endBest) {
            endBest = v;
            endNode = n;
        }
    }
    const bool complete = endNode >= 0;
    // Without a path through the words, the best partial one still places the words it passed.
    if (s.keepPath && s.windowStart < s.frames)
        s.emitPath(s.frames - 1, complete ? endNode : bestNode);
    return s.path.finish(complete);
}

void ForcedAligner::followOnly() {
    auto& s = *state_;
    s.keepPath = false;
    // A window holds at most lookahead + commit frames (push() commits when it is that full),
    // each with the back-pointers of at most every node or the beam's widest range.
    const auto keep = static_cast<std::size_t>(std::lround(s.config.lookaheadSeconds / s.hop));
    const auto every = std::max<std::size_t>(1, std::lround(s.config.commitSeconds / s.hop));
    const auto frames = keep + every + 1;
    const auto nodes = s.graph.nodes.size();
    const auto perFrame = std::min(nodes, static_cast<std::size_t>(s.config.maxActiveNodes) + 1);
    s.rows.reserve(frames);
    s.back.reserve(frames * perFrame);
    s.excess.reserve(frames * s.set->size());
    s.alive.reserve(nodes);
    s.traced.reserve(nodes);
}

void ForcedAligner::phonemesBack(std::span<int> out) const {
    const auto& s = *state_;
    std::fill(out.begin(), out.end(), -1);
    if (s.frames == 0) return;
    int node = firstBest(s.delta, s.lo, s.hi);
    for (std::int64_t f = s.frames - 1, k = 0; k < std::ssize(out) && f >= s.windowStart;
         ++k, --f) {
        const auto& n = s.graph.nodes[static_cast<std::size_t>(node)];
        const bool word =
            n.kind == AlignmentNode::Kind::Phoneme || n.kind == AlignmentNode::Kind::Pause;
        out[static_cast<std::size_t>(k)] = word ? n.phoneme : -1;
        if (f > s.windowStart) node = s.ancestor(f, node, f - 1);
    }
}

double ForcedAligner::minimumSeconds() const {
    return state_->graph.minimumFrames * state_->hop;
}

std::size_t ForcedAligner::peakFramesHeld() const {
    return state_->peakRows;
}

}  // namespace lipsyncd::dsp
