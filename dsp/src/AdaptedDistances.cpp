#include "AdaptedDistances.hpp"

#include <algorithm>
#include <limits>

namespace lipsyncd::dsp {

AdaptedDistances::AdaptedDistances(const TemplateSet& adapted, const TemplateSet& measured,
                                   const PhonemeSet& set)
    : matrix_(adapted, set),
      same_(matrix_.sameBlocks(TemplateMatrix(measured, set))),
      scaledFrame_(matrix_.features()),
      distances_(set.size()) {}

// As FrameClassifier::classify() forms them.
std::span<const float> AdaptedDistances::operator()(const FrameFeatures& frame,
                                                    std::span<const float> record) {
    if (!frame.valid) {  // digital silence or a degenerate frame: nothing to compare
        std::fill(distances_.begin(), distances_.end(), std::numeric_limits<float>::infinity());
        return distances_;
    }
    matrix_.transform(frame.spectrum, scaledFrame_);
    if (record.size() == same_.size())
        matrix_.nearest(scaledFrame_, distances_, same_, record);
    else  // no record: every block measured
        matrix_.nearest(scaledFrame_, distances_);
    matrix_.toRms(distances_);
    return distances_;
}

}  // namespace lipsyncd::dsp
