#include "AlignmentSweep.hpp"

#include <algorithm>

namespace lipsyncd::dsp {

namespace {
// Staying, or the edge from the node before (the edge when strictly cheaper), for the nodes
// [from, to]: the same operations for every node, which the compiler runs side by side once
// told that the arrays do not overlap.
void stayOrEnter(int from, int to, const float* __restrict delta, const float* __restrict loopCost,
                 const float* __restrict leave, const float* __restrict chainCost,
                 const int* __restrict slot, const float* __restrict emission,
                 float* __restrict way, float* __restrict next, std::int32_t* __restrict arg) {
    for (int n = from; n <= to; ++n) {
        const float stay = delta[n] + loopCost[n];
        const float enter = leave[n - 1] + chainCost[n];
        const float in = std::min(stay, enter);
        way[n] = in;
        next[n] = in + emission[slot[n]];                     // +inf stays +inf: no cost is -inf
        const int entered = -static_cast<int>(enter < stay);  // -1: from n - 1
        const int unreached = -static_cast<int>(!(in < kNever));  // -1: all bits set
        arg[n] = (n + entered) | unreached;
    }
}
}  // namespace

AlignmentSweep::AlignmentSweep(const AlignmentGraph& graph, std::size_t classes)
    : classes_(classes), emission_(2 * classes, 0.0f) {
    const int nodes = static_cast<int>(graph.nodes.size());
    restStart_.push_back(0);
    for (int n = 0; n < nodes; ++n) {
        const auto& node = graph.nodes[n];
        int slot = node.silentOnly ? static_cast<int>(classes) + node.phoneme : node.phoneme;
        if (node.kind == AlignmentNode::Kind::Filler) {
            auto at = std::find(emission_.begin() + 2 * static_cast<std::ptrdiff_t>(classes),
                                emission_.end(), node.frameCost);
            if (at == emission_.end()) at = emission_.insert(emission_.end(), node.frameCost);
            slot = static_cast<int>(at - emission_.begin());
        }
        slot_.push_back(slot);
        loopCost_.push_back(node.loopCost);
        exitCost_.push_back(node.exitCost);
        const auto* edges = graph.edges.data() + node.firstEdge;
        const bool chained = node.edgeCount > 0 && edges[0].from == n - 1;
        chainCost_.push_back(chained ? edges[0].cost : kNever);
        if (chained && node.edgeCount == 1) continue;
        junctions_.push_back(n);
        for (int e = chained ? 1 : 0; e < node.edgeCount; ++e)
            rest_.push_back({edges[e].from + 1, edges[e].cost});
        restStart_.push_back(rest_.size());
    }
    leave_.assign(graph.nodes.size() + 1, kNever);
    way_.assign(graph.nodes.size(), kNever);
}

void AlignmentSweep::setSilent(bool silent) {
    for (std::size_t c = 0; c < classes_; ++c)
        emission_[classes_ + c] = silent ? emission_[c] : kNever;
}

void AlignmentSweep::relax(std::span<const float> delta, int lo, int hi, int from, int to,
                           std::span<float> next, std::span<std::int32_t> arg) {
    float* leave = leave_.data() + 1;  // leave[-1]: before the first node, +inf
    for (int m = lo; m <= hi; ++m) leave[m] = delta[m] + exitCost_[m];
    stayOrEnter(from, to, delta.data(), loopCost_.data(), leave, chainCost_.data(), slot_.data(),
                emission_.data(), way_.data(), next.data(), arg.data());
    // The junctions' other edges, in order.
    auto j = std::lower_bound(junctions_.begin(), junctions_.end(), from);
    for (; j != junctions_.end() && *j <= to; ++j) {
        const auto k = static_cast<std::size_t>(j - junctions_.begin());
        float in = way_[*j];
        int a = arg[*j];  // -1 while no way in was found
        for (auto e = restStart_[k]; e < restStart_[k + 1]; ++e) {
            const float v = leave_[rest_[e].from] + rest_[e].cost;
            const int lower = -static_cast<int>(v < in);  // a mask: no branch to mispredict
            a ^= (a ^ (rest_[e].from - 1)) & lower;
            in = std::min(in, v);
        }
        next[*j] = in + emission_[slot_[*j]];
        arg[*j] = a;
    }
    std::fill(leave + lo, leave + hi + 1, kNever);
}

}  // namespace lipsyncd::dsp
