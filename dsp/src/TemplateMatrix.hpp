// Every template of a set, laid out for the classifier's distance loop. Σ w·(x−t)² =
// Σ (√w·x − √w·t)²: templates are stored scaled by √w, or multiplied by the set's whitening W
// (‖W(x − t)‖² = ‖Wx − Wt‖²), so a frame is transformed once and compared with every template. Per
// class, its templates go in blocks of eight (the last block padded with copies of the class's last
// template, which cannot change a minimum), each block feature-major ([feature][8 templates]), so
// that one vector operation serves eight templates and no per-template horizontal sum is needed.
//
// Each template's sum is formed exactly as a row-by-row loop with eight partial sums forms it
// (feature f into partial sum f mod 8, in order; the partial sums added as
// ((0+4)+(1+5))+((2+6)+(3+7))), so the distances do not depend on the layout.
#pragma once

#include <cstddef>
#include <lipsyncd/dsp.hpp>
#include <span>
#include <vector>

namespace lipsyncd::dsp {

// A set's distance as a plain Euclidean one: features scaled by √w (the per-feature weights), or
// multiplied by the set's whitening W (lower triangular), so that ‖T(x) − T(t)‖² is the set's
// distance between a frame x and a template t.
class FeatureWeighting {
  public:
    FeatureWeighting() = default;
    explicit FeatureWeighting(const TemplateSet& templates);
    std::size_t features() const { return features_; }
    // `out` has features() values.
    void transform(std::span<const float> frame, std::span<float> out) const;

  private:
    std::size_t features_ = 0;
    std::vector<float> scale_;
    std::vector<float> whitening_;  // [row][column], row-major; empty: diagonal scale_ only
};

class TemplateMatrix {
  public:
    static constexpr std::size_t kLanes = 8;

    TemplateMatrix() = default;
    // Throws InputError for a class the phoneme set does not have.
    TemplateMatrix(const TemplateSet& templates, const PhonemeSet& set);
    std::size_t features() const { return weighting_.features(); }
    // The frame as nearest() takes it (FeatureWeighting). `out` has features() values.
    void transform(std::span<const float> frame, std::span<float> out) const {
        weighting_.transform(frame, out);
    }
    // Squared weighted distance from a scaled frame to the nearest template of each class,
    // indexed by phoneme set index; +inf for classes without templates.
    void nearest(std::span<const float> scaledFrame, std::span<float> out) const;

  private:
    FeatureWeighting weighting_;
    std::vector<float> blocks_;    // [block][feature][lane]
    std::vector<int> blockClass_;  // phoneme set index of each block (blocks of a class adjacent)
};

}  // namespace lipsyncd::dsp
