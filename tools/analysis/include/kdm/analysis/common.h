// Shared conventions of the point-set analysis (docs/design.md §6): the point representation, the reference
// spacings that normalise every distance (d_hex in 2D, the FCC spacing in 3D), input validation and the
// minimum-image displacement used for periodic (torus) distances.
#pragma once

#include <array>
#include <cstddef>
#include <stdexcept>
#include <vector>

namespace kdm::analysis {

// Points are passed as interleaved coordinates `const std::vector<double>& coords` (x0 y0 x1 y1 ... or
// x0 y0 z0 ...), `dim` (2 or 3) per point, normalised to the unit square/cube [0,1)^dim. A flag `torus`
// selects periodic (minimum-image) distances; otherwise the domain is a bounded box. A set drawn in a
// rectangle (box) has its points normalised all the same; `Sides` then say the domain's side lengths,
// scaled to unit area (volume), and every distance is measured in them.

/// Side lengths of the domain, x y z, in units where it has area (2D) or volume (3D) 1: {1, 1, 1} is the
/// unit square (cube); a 2:1 rectangle is {√2, 1/√2, 1}. A coordinate v ∈ [0, 1] lies at v · side.
using Sides = std::array<double, 3>;
inline constexpr Sides kUnitSides = {1, 1, 1};

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

/// The sides of a domain of relative side lengths `extent` (x y z; only the first `dim` are read) scaled to
/// unit area (2D) or volume (3D): extent {2, 1} gives {√2, 1/√2}; all-equal sides give exactly 1 each.
/// Throws InvalidInput for a side that is not a positive finite number, or sides more than 10^4 apart.
/// Thread-safe (pure).
Sides unit_measure_sides(const double* extent, int dim);

/// Whether `sides` are the unit square's (cube's): every one exactly 1.
inline bool unit_sides(const Sides& sides) {
  return sides[0] == 1 && sides[1] == 1 && sides[2] == 1;
}

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

/// axis_delta in the domain's lengths: the normalised displacement times the axis's `side` (a period of
/// `side` on the torus). A side of 1 gives axis_delta's bits.
inline double axis_delta(double a, double b, bool torus, double side) {
  return axis_delta(a, b, torus) * side;
}

}  // namespace kdm::analysis
