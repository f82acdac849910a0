// The whitening transform of a Mahalanobis distance: W with Wᵀ W = Σ⁻¹, so that
// ‖W(x − t)‖² = (x − t)ᵀ Σ⁻¹ (x − t).
#pragma once

#include <cstddef>
#include <span>
#include <vector>

namespace lipsyncd::dsp {

// From a symmetric positive-definite covariance (n × n, row-major): W = s · L⁻¹, L the Cholesky
// factor of Σ (Σ = L Lᵀ), lower triangular. `s` rescales the distance so that it keeps the units
// of the features (see TemplateTrainer::build). Returns the n rows of W. Throws InputError when Σ
// is not positive definite.
std::vector<std::vector<float>> whiteningFromCovariance(std::span<const double> covariance,
                                                        std::size_t n, double s);

}  // namespace lipsyncd::dsp
