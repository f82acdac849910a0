// A frame as the forced aligner takes it (AlignerConfig::classNetworkShare): the templates'
// distances plus a share of what the class network adds to them, the words' confidences kept on
// the templates' own. alignFile and LineFollower feed the aligner alike through these.
#pragma once

#include <cmath>
#include <lipsyncd/dsp.hpp>
#include <span>
#include <vector>

namespace lipsyncd::dsp {

// What the class network and the set's class bias add to a frame's template distances
// (FrameClassifier::distances() over templateDistances()), per class; 0 where either is not
// finite (a class without templates keeps its distance as the templates give it).
inline void networkTerm(std::span<const float> templates, std::span<const float> full,
                        std::span<float> term) {
    for (std::size_t c = 0; c < term.size(); ++c)
        term[c] =
            std::isfinite(templates[c]) && std::isfinite(full[c]) ? full[c] - templates[c] : 0.0f;
}

// One frame into the aligner: the templates' distances, plus `share` of the network's term
// (AlignerConfig::classNetworkShare) when it is on; the words' confidences then stay on the
// templates' own (ForcedAligner::push). `mixed` is room for the sum.
inline void pushFrame(ForcedAligner& aligner, double time, std::span<const float> templates,
                      std::span<const float> term, float share, bool silent,
                      std::vector<float>& mixed) {
    if (share <= 0) {
        aligner.push(time, templates, silent);
        return;
    }
    mixed.resize(templates.size());
    for (std::size_t c = 0; c < templates.size(); ++c) mixed[c] = templates[c] + share * term[c];
    aligner.push(time, mixed, silent, templates);
}

}  // namespace lipsyncd::dsp
