// The state graph of a forced alignment: a start node; then, for every gap between words (and
// before the first and after the last), an optional pause and an optional filler (after the
// last word two fillers: one straight after it, one only after a pause heard); and for every
// phoneme of every word a chain of minimum-duration nodes, the last with a self-loop (a geometric
// tail; Rabiner 1989, section IV.D) whose mean is what the expected duration leaves after
// tailFractionOfExpected of it (AlignerConfig: the minimum itself is longer). A word
// said more than one way (reductions) has one such run of chains per pronunciation, in parallel.
// Nodes are in time order: every edge goes forward, so the Viterbi pass is one sweep.
#pragma once

#include <limits>
#include <lipsyncd/dsp.hpp>
#include <vector>

namespace lipsyncd::dsp {

inline constexpr float kNever = std::numeric_limits<float>::infinity();

struct AlignmentNode {
    enum class Kind { Start, Pause, Filler, Phoneme };
    Kind kind = Kind::Phoneme;
    int phoneme = 0;  // phoneme set index (Pause: silence)
    int word = -1;    // word index (Phoneme) or the gap's index (Pause, Filler: before word)
    int phone = -1;   // running index of the phoneme in the script (Phoneme)
    float loopCost = kNever;           // staying another frame
    float frameCost = 0;               // Filler: its cost per frame (AlignerConfig)
    bool silentOnly = false;           // Pause: only on frames below the energy gate
    float exitCost = 0;                // leaving (the tail's end probability)
    int firstEdge = 0, edgeCount = 0;  // incoming edges
};

struct AlignmentEdge {
    int from = 0;
    float cost = 0;
    bool skips = false;  // leaves out words between its ends
};

struct AlignmentGraph {
    std::vector<AlignmentNode> nodes;
    std::vector<AlignmentEdge> edges;  // grouped by target node
    std::vector<int> reach;            // reach[n]: the furthest node any node ≤ n leads to
    std::vector<float> endCost;        // per node: cost of ending there (+inf: not an end)
    // per node: the fewest frames a path there needs after this one to say every word left
    std::vector<int> framesToEnd;
    int words = 0, phones = 0;
    int minimumFrames = 0;       // the shortest path through every word
    double expectedSeconds = 0;  // the synthesiser's durations, times the time scale
    std::vector<double> wordExpectedSeconds;

    static AlignmentGraph build(std::span<const ScriptWord> script, const PhonemeSet& set,
                                double hopSeconds, double timeScale, const AlignerConfig& config);
};

}  // namespace lipsyncd::dsp
