#pragma once

#include <span>
#include <vector>

// Numerical kernels the synthesis's parts share.
namespace sonarbench::sim {

/// to[k] += w · from[k] for every k, vectorised; every CPU gives the same bits (kernels.cpp).
void AddScaled(std::span<double> to, std::span<const double> from, double w);

/// c_e = exp(-|e| / steps) for |e| up to `max_reach` or to where what is left holds under 1e-12
/// of the power, whichever is nearer (entry e + reach): the kernel that makes draws e-fold their
/// correlation over `steps` head steps.
[[nodiscard]] std::vector<double> ExponentialKernel(double steps, int max_reach);

}  // namespace sonarbench::sim
