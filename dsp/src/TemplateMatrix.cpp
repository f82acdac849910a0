#include "TemplateMatrix.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "VectorLanes.hpp"

namespace lipsyncd::dsp {

FeatureWeighting::FeatureWeighting(const TemplateSet& templates)
    : features_(templates.binWeights.size()) {
    scale_.resize(features_);
    for (std::size_t b = 0; b < features_; ++b) scale_[b] = std::sqrt(templates.binWeights[b]);
    for (const auto& row : templates.whitening)
        whitening_.insert(whitening_.end(), row.begin(), row.end());
}

void FeatureWeighting::transform(std::span<const float> frame, std::span<float> out) const {
    if (whitening_.empty()) {
        for (std::size_t b = 0; b < features_; ++b) out[b] = frame[b] * scale_[b];
        return;
    }
    for (std::size_t r = 0; r < features_; ++r) {  // lower triangular: columns 0..r
        const float* row = whitening_.data() + r * features_;
        float sum = 0;
        for (std::size_t c = 0; c <= r; ++c) sum += row[c] * frame[c];
        out[r] = sum;
    }
}

TemplateMatrix::TemplateMatrix(const TemplateSet& templates, const PhonemeSet& set)
    : weighting_(templates) {
    const std::size_t features = weighting_.features();
    std::vector<float> stored(features);
    for (const auto& c : templates.classes) {
        const auto idx = set.find(c.phoneme);
        if (!idx)
            throw InputError("templates: class '" + c.phoneme + "' is not in the phoneme set");
        for (std::size_t first = 0; first < c.spectra.size(); first += kLanes) {
            const std::size_t at = blocks_.size();
            blocks_.resize(at + features * kLanes);
            for (std::size_t lane = 0; lane < kLanes; ++lane) {
                transform(c.spectra[std::min(first + lane, c.spectra.size() - 1)], stored);
                for (std::size_t b = 0; b < features; ++b)
                    blocks_[at + b * kLanes + lane] = stored[b];
            }
            blockClass_.push_back(static_cast<int>(*idx));
        }
    }
}

namespace {
// Eight templates at once, one per lane.
using Lanes = FloatLanes;
static_assert(TemplateMatrix::kLanes == kVectorLanes, "a block is one vector of lanes");

// Beside the distances: each block's least distance recorded, or some blocks' taken as known.
struct BlockRecord {
    float* write = nullptr;               // per block, or null
    const std::uint8_t* known = nullptr;  // per block: 1 where `values` holds it, or null
    const float* values = nullptr;
};

// The least of the lanes that are numbers, as the running minimum below keeps them.
float leastLane(const Lanes& v) {
    float m = std::numeric_limits<float>::infinity();
    for (std::size_t lane = 0; lane < TemplateMatrix::kLanes; ++lane) m = v[lane] < m ? v[lane] : m;
    return m;
}

// Squared distances from x to the eight templates of one block. Feature f goes into partial
// sum f mod 8, as in a row loop of eight partial sums.
LIPSYNCD_VECTOR_CLONES void nearestPerClass(const float* x, std::size_t features,
                                            const float* blocks, const int* blockClass,
                                            std::size_t blockCount, BlockRecord record,
                                            float* out) {
    const std::size_t stride = features * TemplateMatrix::kLanes;
    const std::size_t whole = features / 8 * 8;
    for (std::size_t block = 0; block < blockCount;) {
        const int cls = blockClass[block];
        Lanes best;
        for (std::size_t lane = 0; lane < TemplateMatrix::kLanes; ++lane)
            best[lane] = std::numeric_limits<float>::infinity();
        float known = std::numeric_limits<float>::infinity();
        for (; block < blockCount && blockClass[block] == cls; ++block) {
            if (record.known && record.known[block]) {
                known = std::min(known, record.values[block]);
                continue;
            }
            const float* t = blocks + block * stride;
            Lanes acc[8] = {};
            std::size_t f = 0;
            for (; f < whole; f += 8)
#pragma GCC unroll 8
                for (std::size_t k = 0; k < 8; ++k) {
                    Lanes row;
                    std::memcpy(&row, t + (f + k) * TemplateMatrix::kLanes, sizeof row);
                    const Lanes d = x[f + k] - row;
                    acc[k] += d * d;
                }
#pragma GCC unroll 8
            for (std::size_t k = 0; k < 8; ++k)
                if (f + k < features) {
                    Lanes row;
                    std::memcpy(&row, t + (f + k) * TemplateMatrix::kLanes, sizeof row);
                    const Lanes d = x[f + k] - row;
                    acc[k] += d * d;
                }
            const Lanes sum =
                ((acc[0] + acc[4]) + (acc[1] + acc[5])) + ((acc[2] + acc[6]) + (acc[3] + acc[7]));
            best = sum < best ? sum : best;
            if (record.write) record.write[block] = leastLane(sum);
        }
        float m = best[0];
        for (std::size_t lane = 1; lane < TemplateMatrix::kLanes; ++lane)
            m = std::min(m, best[lane]);
        out[cls] = std::min(m, known);
    }
}
}  // namespace

void TemplateMatrix::nearest(std::span<const float> scaledFrame, std::span<float> out) const {
    std::fill(out.begin(), out.end(), std::numeric_limits<float>::infinity());
    nearestPerClass(scaledFrame.data(), features(), blocks_.data(), blockClass_.data(),
                    blockClass_.size(), {}, out.data());
}

void TemplateMatrix::nearest(std::span<const float> scaledFrame, std::span<float> out,
                             std::span<float> record) const {
    std::fill(out.begin(), out.end(), std::numeric_limits<float>::infinity());
    nearestPerClass(scaledFrame.data(), features(), blocks_.data(), blockClass_.data(),
                    blockClass_.size(), {record.data()}, out.data());
}

void TemplateMatrix::nearest(std::span<const float> scaledFrame, std::span<float> out,
                             std::span<const std::uint8_t> same,
                             std::span<const float> record) const {
    std::fill(out.begin(), out.end(), std::numeric_limits<float>::infinity());
    nearestPerClass(scaledFrame.data(), features(), blocks_.data(), blockClass_.data(),
                    blockClass_.size(), {nullptr, same.data(), record.data()}, out.data());
}

std::vector<std::uint8_t> TemplateMatrix::sameBlocks(const TemplateMatrix& other) const {
    std::vector<std::uint8_t> same(blocks(), 0);
    if (!(weighting_ == other.weighting_) || blockClass_ != other.blockClass_) return same;
    const std::size_t stride = features() * kLanes;
    for (std::size_t b = 0; b < blocks(); ++b)
        same[b] = std::memcmp(&blocks_[b * stride], &other.blocks_[b * stride],
                              stride * sizeof(float)) == 0;
    return same;
}

void TemplateMatrix::toRms(std::span<float> distances) const {
    const auto n = static_cast<float>(features());
    for (auto& d : distances)
        if (std::isfinite(d)) d = std::sqrt(d / n);
}

}  // namespace lipsyncd::dsp
