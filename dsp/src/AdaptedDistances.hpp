// The templates' distances (FrameClassifier::templateDistances()) of frames a first pass has
// measured already, on a set in which only some templates moved (SpeakerAdaptation::adapted):
// the blocks of templates that did not move are taken from the first pass's record of the frame
// (FrameClassifier::blockDistances()), the others measured again. The same distances as a
// classifier on the moved set gives, at about half the cost for a file's second pass.
#pragma once

#include <cstdint>
#include <lipsyncd/dsp.hpp>
#include <span>
#include <vector>

#include "TemplateMatrix.hpp"

namespace lipsyncd::dsp {

class AdaptedDistances {
  public:
    // `measured`: the set the first pass classified with.
    AdaptedDistances(const TemplateSet& adapted, const TemplateSet& measured,
                     const PhonemeSet& set);
    // `record`: the first pass's block distances for this frame. Valid until the next call.
    std::span<const float> operator()(const FrameFeatures& frame, std::span<const float> record);

  private:
    TemplateMatrix matrix_;
    std::vector<std::uint8_t> same_;  // per block: taken from the record
    std::vector<float> scaledFrame_, distances_;
};

}  // namespace lipsyncd::dsp
