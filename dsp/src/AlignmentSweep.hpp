// One frame of the forced aligner's Viterbi recursion (ForcedAligner), over the graph laid out
// for it. Most nodes are entered only from the node before them (a phoneme's chain): for every
// node, staying and that edge are weighed in one loop over arrays of their own, with no branch
// on the graph's shape, which the compiler vectorises; the few other nodes (where words and gaps
// meet) then go through their other edges. The sums and the order in which candidates are
// compared are those of the plain recursion: staying first, then each edge in the graph's
// order, the first of equal costs winning; a way in costs (delta + exit cost) + edge cost.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "AlignmentGraph.hpp"

namespace lipsyncd::dsp {

class AlignmentSweep {
  public:
    AlignmentSweep(const AlignmentGraph& graph, std::size_t classes);

    // This frame's cost of each class (`classes` values), filled by the caller before relax().
    std::span<float> classCosts() { return std::span(emission_).first(classes_); }
    // After classCosts(): nodes heard only below the energy gate cost +inf in a frame above it.
    void setSilent(bool silent);

    // For every node in [from, to]: the cost of its best way in from the nodes active last
    // frame (`delta`, +inf outside [lo, hi]) plus its emission, in `next`, and the node it came
    // from in `arg` (-1: unreachable, `next` +inf).
    void relax(std::span<const float> delta, int lo, int hi, int from, int to,
               std::span<float> next, std::span<std::int32_t> arg);

  private:
    std::size_t classes_;
    // Per slot: each class's cost this frame, the same for silent-only nodes (+inf above the
    // gate), then the fillers' fixed costs per frame.
    std::vector<float> emission_;
    std::vector<int> slot_;        // per node: its emission slot
    std::vector<float> loopCost_;  // per node: +inf without a loop
    std::vector<float> exitCost_;  // per node
    // Per node: the cost of its edge from the node before, when that is its first edge (+inf
    // otherwise: then all its edges are a junction's).
    std::vector<float> chainCost_;
    struct Edge {
        int from;
        float cost;
    };
    // Nodes with an edge in besides the one from the node before, in order; junction j's edges
    // after that one: rest_[restStart_[j] .. restStart_[j + 1]), `from` counted as in leave_.
    std::vector<int> junctions_;
    std::vector<std::size_t> restStart_;
    std::vector<Edge> rest_;
    // Per node, after one before the first (never active): delta + exit cost over the active
    // nodes, +inf elsewhere, so an edge from outside them loses without a test.
    std::vector<float> leave_;
    std::vector<float> way_;  // per node: its best way in this frame, before its emission
};

}  // namespace lipsyncd::dsp
