// Shared conventions of the point-set analysis (docs/design.md §6): the point representation, the reference
// spacings that normalise every distance (d_hex in 2D, the FCC spacing in 3D), input validation and the
// minimum-image displacement used for periodic (torus) distances.
#pragma once

#include <cstddef>
#include <stdexcept>
#include <vector>

namespace kdm::analysis {

// Points are passed as interleaved coordinates `const std::vector<double>& coords` (x0 y0 x1 y1 ... or
// x0 y0 z0 ...), `dim` (2 or 3) per point, normalised to the unit square/cube [0,1)^dim. A flag `torus`
// selects periodic (minimum-image) distances; otherwise the domain is a bounded box.

/// Thrown for invalid input (wrong dimension, coordinates outside [0,1], non-finite values, too few points).
struct InvalidInput : std::invalid_argument {
  using std::invalid_argument::invalid_argument;
};

/// Hexagonal-packing spacing for `n` points in the unit square: d_hex = sqrt(2 / (sqrt(3) n)).
/// Unit: lengths of the unit square. Returns +inf for n = 0. Thread-safe (pure).
double hex_spacing(std::size_t n);

/// Face-centred-cubic nearest-neighbour spacing for `n` points in the unit cube: (sqrt(2) / n)^(1/3).
/// Unit: lengths of the unit cube. Returns +inf for n = 0. Thread-safe (pure).
double fcc_spacing(std::size_t n);

/// hex_spacing(n) for dim 2, fcc_spacing(n) for dim 3; throws InvalidInput for other dimensions.
double reference_spacing(int dim, std::size_t n);

/// Checks dim ∈ {2,3}, coords.size() a multiple of dim, every coordinate finite and inside [0, 1]
/// (1 itself is accepted: writers often round 0.99999999 up). Throws InvalidInput with a one-line message.
/// Thread-safe (reads only).
void validate_points(const std::vector<double>& coords, int dim);

/// Component of the displacement b − a along one axis; on the torus the minimum image in [−1/2, 1/2].
inline double axis_delta(double a, double b, bool torus) {
  double d = b - a;
  if (torus) {
    if (d > 0.5)
      d -= 1.0;
    else if (d < -0.5)
      d += 1.0;
  }
  return d;
}

}  // namespace kdm::analysis
