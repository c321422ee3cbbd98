// Labelled point sets (several classes, multi-class blue noise as in L.-Y. Wei, "Multi-class blue noise
// sampling", SIGGRAPH 2010): each class alone, and how close points of different classes come.
#pragma once

#include <cstdint>
#include <vector>

#include "point_io.h"

namespace kdm::analysis {

/// The classes present in `set` (ascending); empty for an unlabelled set.
std::vector<std::uint8_t> classes_present(const tools::PointSet& set);

/// The points of `set` whose class is `k`, unlabelled.
tools::PointSet class_subset(const tools::PointSet& set, std::uint8_t k);

/// The distance between the closest two points of different classes, in hexagonal spacings of the whole
/// set (hex_spacing(n)); NaN with fewer than two classes. 2D points in [0, 1]²; `torus`: periodic
/// distances. Throws InvalidInput for an unlabelled or 3D set.
double cross_class_closest(const tools::PointSet& set, bool torus);

}  // namespace kdm::analysis
